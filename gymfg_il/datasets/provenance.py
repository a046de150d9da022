"""Episode metadata (the ``gymfg/*`` columns) after LeRobot's own dataset editing.

``lerobot-edit-dataset`` (delete_episodes, split, merge, remove_feature) rebuilds
``meta/episodes`` with LeRobot's columns only, so the ``gymfg/*`` columns (aircraft, task,
seed, source, flight spec, ...) go, and with them what each episode was. Nothing else of ours
can ride along: a top-level ``info.json`` key is dropped, and a table inside a feature's
description survives delete and split but makes LeRobot's merge refuse the datasets (it
wants identical features). The frames survive every edit, though, so an episode is known by
its fingerprint (its length and first observation), and ``restore`` (``collect repair DIR
--source ORIGINAL``) takes each edited episode's columns from the dataset(s) it came from.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError

PREFIX = "gymfg/"


def fingerprint(first_observation: np.ndarray, length: int) -> str:
    """What identifies an episode across LeRobot's edits: its length and first observation."""
    data = np.ascontiguousarray(first_observation, dtype=np.float32).tobytes()
    return hashlib.blake2b(data + int(length).to_bytes(8, "little"), digest_size=8).hexdigest()


def fingerprints(root: Path, meta: Any) -> list[str]:
    """Each episode's fingerprint, in episode order, from the dataset's data files."""
    import pyarrow.parquet as pq

    firsts: dict[int, np.ndarray] = {}
    for path in sorted((Path(root) / "data").rglob("*.parquet")):
        table = pq.read_table(path, columns=["episode_index", "frame_index", "observation.state"])
        frame = table["frame_index"].to_numpy()
        episode = table["episode_index"].to_numpy()
        for row in np.flatnonzero(frame == 0):
            state = table["observation.state"][int(row)].as_py()
            firsts[int(episode[row])] = np.asarray(state, dtype=np.float32)
    lengths = list(meta.episodes["length"])
    missing = [i for i in range(len(lengths)) if i not in firsts]
    if missing:
        raise ConfigError(f"the dataset at {root} has no first frame for episodes {missing[:5]}")
    return [fingerprint(firsts[i], n) for i, n in enumerate(lengths)]


def metadata_columns(meta: Any) -> dict[str, list[Any]]:
    """The ``gymfg/*`` columns of every episode, in episode order ({} when there are none:
    not our dataset, older than them, or edited by LeRobot's tools: ``restore``)."""
    episodes = meta.episodes
    if episodes is None:
        return {}
    return {c: list(episodes[c]) for c in episodes.column_names if c.startswith(PREFIX)}


def restore(root: Path, meta: Any, sources: Sequence[Path]) -> int:
    """Write the ``gymfg/*`` columns into ``meta/episodes`` of the dataset at ``root`` (each
    file replaced atomically), each episode's taken from the source dataset that holds the
    same episode (by ``fingerprint``); the number of episodes restored (0: they have them)."""
    from gymfg_il.datasets import lerobot_api as lr

    if metadata_columns(meta):
        return 0
    known: dict[str, dict[str, Any]] = {}
    for source in sources:
        source_meta = lr.open_metadata(source)
        columns = metadata_columns(source_meta)
        if not columns:
            raise ConfigError(f"the source dataset {source} has no gymfg/* columns either")
        for i, key in enumerate(fingerprints(source, source_meta)):
            known[key] = {name: values[i] for name, values in columns.items()}
    keys = fingerprints(root, meta)
    missing = [i for i, key in enumerate(keys) if key not in known]
    if missing:
        raise ConfigError(
            f"{len(missing)} of the {len(keys)} episodes of {root} (the first: {missing[:5]}) "
            "are in none of the sources; give every dataset it was edited from (--source, "
            "repeatable)"
        )
    names = sorted({name for key in keys for name in known[key]})
    values = {name: {e: known[key].get(name) for e, key in enumerate(keys)} for name in names}
    return write_columns(root, values)


def write_columns(root: Path, columns: dict[str, dict[int, Any]]) -> int:
    """Set values of the episode table's ``columns`` (each {episode index: value}; an
    episode left out keeps its value), adding the columns it lacks; each file replaced
    atomically. The number of episodes in the files written."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    done = 0
    for path in sorted((Path(root) / "meta" / "episodes").rglob("*.parquet")):
        table = pq.read_table(path)
        index = table["episode_index"].to_numpy()
        if not any(int(i) in values for values in columns.values() for i in index):
            continue
        for name, values in columns.items():
            at = table.schema.get_field_index(name)
            old = table[name].to_pylist() if at >= 0 else [None] * len(index)
            column = pa.array([values.get(int(i), v) for i, v in zip(index, old, strict=True)])
            table = (
                table.append_column(name, column) if at < 0 else table.set_column(at, name, column)
            )
        tmp = path.with_name(f"{path.name}.tmp-{os.getpid()}")
        pq.write_table(table, tmp)
        os.replace(tmp, path)
        done += len(index)
    return done
