"""Checking what a dataset holds against the logs it was built from.

The logs are the truth: a dataset is rebuilt from them whenever it differs. ``differences``
reads every frame of the data files (their page checksums verified, where the builder wrote
them) and compares each episode with the log episode it names, column by column as the
builder stores it (float32 state, action and reward, the done and intervention flags, the
environment state), and LeRobot's bookkeeping (episode, frame and global indexes, timestamps,
task index) with what the episode table says. An episode no log holds is not checked: a
rebuild could not replace it. Two episodes with the same frames, both of logs, are one
episode twice. An episode's record (its ``gymfg/*`` columns: verdict, pilot, seed, times...)
is checked too (``train bc --select`` chooses episodes by it), but for the pilot's mark: a
pilot may mark an episode after the dataset took it, and the build then takes the new mark.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets.episode_logs import EpisodeRef
from gymfg_il.datasets.episode_record import record_differences
from gymfg_il.datasets.features import ENVIRONMENT_STATE
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.sim.properties import task_columns

MARK = "gymfg/mark"  # the pilot's own mark, which the log may give after the episode ended
_BOOKKEEPING = ("episode_index", "frame_index", "index", "timestamp", "task_index")


def digest(state: np.ndarray, action: np.ndarray) -> str:
    """What identifies an episode's frames: its float32 states and actions, as stored."""
    h = hashlib.blake2b(digest_size=16)
    for values in (state, action):
        a = np.ascontiguousarray(values, dtype=np.float32)
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _column(table: Any, name: str) -> np.ndarray:
    """A column as numpy: lists of one length (a fixed-size list, or the plain lists that
    LeRobot's own editing writes) as (rows, width); ValueError for lists of other lengths."""
    import pyarrow as pa
    import pyarrow.compute as pc

    column = table[name].combine_chunks()
    if pa.types.is_fixed_size_list(column.type):
        width = column.type.list_size
        return column.flatten().to_numpy(zero_copy_only=False).reshape(-1, width)
    if pa.types.is_list(column.type) or pa.types.is_large_list(column.type):
        lengths = pc.list_value_length(column).to_numpy(zero_copy_only=False)
        if len(column) and (column.null_count or (lengths != lengths[0]).any()):
            raise ValueError(f"its {name} column holds vectors of different lengths")
        width = int(lengths[0]) if len(column) else 0
        return column.flatten().to_numpy(zero_copy_only=False).reshape(-1, width)
    return column.to_numpy(zero_copy_only=False)


def _frames(root: Path, features: Mapping[str, Any]) -> tuple[dict[str, np.ndarray], list[str]]:
    """Every data file's non-video columns, concatenated; and what could not be read."""

    names = [k for k, f in features.items() if f.get("dtype") != "video"]
    names += [k for k in _BOOKKEEPING if k not in names]
    tables, problems = _read(root, names)
    if problems or not tables:
        return {}, problems or ["data/ holds no data files"]
    try:  # file by file: LeRobot's editing writes plain lists where ours are fixed-size
        parts = [{name: _column(t, name) for name in t.column_names} for t in tables]
        return {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}, []
    except ValueError as err:
        return {}, [f"data/: {err}"]


def page_problems(root: Path, features: Mapping[str, Any]) -> list[str]:
    """What in the data files of the dataset at ``root`` fails its page checksums (where the
    builder wrote them) or cannot be decoded: damage that may still read as numbers."""
    names = [k for k, f in features.items() if f.get("dtype") != "video"]
    return _read(root, names)[1]


def _read(root: Path, names: list[str]) -> tuple[list[Any], list[str]]:
    """The ``names`` columns of each data file (Arrow tables), their page checksums verified;
    and what could not be read."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    tables, problems = [], []
    for path in sorted((root / "data").rglob("*.parquet")):
        where = path.relative_to(root)
        try:
            handle = pq.ParquetFile(path, page_checksum_verification=True)
        except Exception as err:  # pyarrow raises several types for a damaged file
            problems.append(f"{where} cannot be read ({err})")
            continue
        columns, bad = {}, []
        for name in names:
            try:
                columns[name] = handle.read(columns=[name])[name]
            except Exception as err:  # a page that fails its checksum, or will not decode
                bad.append(f"{where}: its {name} column cannot be read ({err})")
        problems += bad
        if not bad:
            tables.append(pa.table(columns))
    return tables, problems


def _expected(
    columns: Mapping[str, np.ndarray], features: Mapping[str, Any]
) -> dict[str, np.ndarray]:
    """The frames the builder writes for a log episode's ``columns``, as stored."""
    out = {k: np.asarray(v) for k, v in columns.items() if k in features}
    if ENVIRONMENT_STATE in features:
        names = features["observation.state"]["names"]
        out[ENVIRONMENT_STATE] = out["observation.state"][:, task_columns(names)]
    return {k: v.astype(features[k]["dtype"]) for k, v in out.items()}


def _first_difference(have: np.ndarray, want: np.ndarray) -> int:
    """The first frame where ``have`` and ``want`` differ (NaN equals NaN)."""
    same = have == want
    if have.dtype.kind == "f":
        same |= np.isnan(have) & np.isnan(want)
    return int(np.argmin(same.reshape(len(same), -1).all(axis=1)))


@dataclass
class Checked:
    """What ``differences`` found in a dataset."""

    problems: list[str]  # what differs from its logs or itself, one line each
    digests: list[str] = field(default_factory=list)  # each episode's ``digest``
    # episodes whose pilot's mark the log gave after they were built: episode -> mark
    marks: dict[int, str] = field(default_factory=dict)


def _bookkeeping(
    frames: Mapping[str, np.ndarray], rows: np.ndarray, start: int, meta: Any
) -> list[str]:
    """LeRobot's columns of one episode's ``rows`` that are not as a build writes them."""
    steps = np.arange(len(rows))
    task = frames["task_index"][rows]
    tasks = len(meta.tasks) if meta.tasks is not None else 0
    book = {
        "frame_index": np.array_equal(frames["frame_index"][rows], steps),
        "index": np.array_equal(frames["index"][rows], start + steps),
        "timestamp": np.array_equal(
            frames["timestamp"][rows], (steps / float(meta.fps)).astype(np.float32)
        ),
        "task_index": bool((task == task[0]).all() and 0 <= task[0] < tasks),
    }
    return [f"its {k} column is not as written" for k, ok in book.items() if not ok]


def _frame_problems(
    frames: Mapping[str, np.ndarray],
    rows: np.ndarray,
    columns: Mapping[str, np.ndarray],
    features: Mapping[str, Any],
) -> list[str]:
    """Each column of one episode's ``rows`` that is not what its log's ``columns`` give."""
    problems = []
    for key, want in _expected(columns, features).items():
        have = frames[key][rows]
        if have.shape != want.shape:
            problems.append(f"{key} has shape {have.shape}, its log {want.shape}")
        elif not np.array_equal(have, want, equal_nan=have.dtype.kind == "f"):
            problems.append(f"{key} differs from its log at frame {_first_difference(have, want)}")
    return problems


def differences(
    root: Path,
    meta: Any,
    logged: Mapping[EpisodeRef, Mapping[str, np.ndarray]],
    refs: list[EpisodeRef | None],
    records: Mapping[EpisodeRef, Mapping[str, Any]],
) -> Checked:
    """What in the dataset at ``root`` differs from its logs or itself. ``logged``: the
    columns of every log episode at hand (``episode_record.episode_columns``), ``records``
    their ``gymfg/*`` columns (``episode_record.episode_metadata``); ``refs``: the log
    episode each dataset episode names."""
    features = meta.features
    frames, problems = _frames(root, features)
    if problems:
        return Checked(problems)
    stored = metadata_columns(meta)
    marks: dict[int, str] = {}
    episodes = meta.episodes
    order = np.argsort(frames["episode_index"], kind="stable")
    held, starts, counts = np.unique(
        frames["episode_index"][order], return_index=True, return_counts=True
    )
    where = {int(e): order[s : s + n] for e, s, n in zip(held, starts, counts, strict=True)}
    digests: list[str] = []
    seen: dict[str, int] = {}
    for e in range(len(episodes)):
        row = episodes[e]
        ref = refs[e] if e < len(refs) else None
        name = f"dataset episode {e} ({ref})"
        rows = where.pop(e, np.zeros(0, dtype=np.int64))
        digests.append(digest(frames["observation.state"][rows], frames["action"][rows]))
        if ref is None or ref not in logged:
            continue  # nothing could replace it: left as it is
        n, start = int(row["length"]), int(row["dataset_from_index"])
        if len(rows) != n or int(row["dataset_to_index"]) != start + n:
            problems.append(f"{name}: the data files hold {len(rows)} frames, its table {n}")
            continue
        problems += [f"{name}: {p}" for p in _bookkeeping(frames, rows, start, meta)]
        record = dict(records[ref])
        if MARK in stored and stored[MARK][e] != record["mark"]:
            marks[e] = record.pop("mark")  # marked after it was built: not a difference
        changed = record_differences({k: v[e] for k, v in stored.items()}, record)
        problems += [f"{name}: {c}" for c in changed]
        twin = seen.setdefault(digests[-1], e)
        if twin != e:
            problems.append(f"{name}: the same episode as dataset episode {twin}")
        problems += [f"{name}: {p}" for p in _frame_problems(frames, rows, logged[ref], features)]
    if where:
        problems.append(
            f"the data files hold frames of episodes {sorted(where)[:5]} no table lists"
        )
    return Checked(problems, digests, marks)
