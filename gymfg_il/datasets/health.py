"""Whether a LeRobot dataset on disk is whole, and what is wrong with it when it is not.

LeRobot itself, given a dataset with a file missing, tries to download the rest from the Hub
(and, offline, fails with a network error that says nothing about the dataset). This looks
first: the files are regular files (``file_problems``), the metadata files parse, the
statistics and task table are there, and the data files are readable parquet holding every
frame the metadata counts.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.files import JSON_LIMIT, PARQUET_LIMIT, VIDEO_LIMIT, regular_problem

# the files of a dataset that are read, by suffix, and the most read of each
READ = {".json": JSON_LIMIT, ".parquet": PARQUET_LIMIT, ".mp4": VIDEO_LIMIT}
REPLACE = (
    "put the file itself there (a link to a regular file is fine), or move the dataset "
    "aside and rebuild it from its logs with `python -m gymfg_il.collect recover SESSION`"
)


def file_problems(root: Path) -> list[str]:
    """Each file of the dataset at ``root`` that is read (``meta/``, ``data/`` and
    ``videos/``: JSON, parquet, video) but is not a regular file, or is larger than one
    can be: a FIFO in a file's place hangs its reader, a link to /dev/zero fills memory.
    One line each, the file's path in the dataset first."""
    problems = []
    for part in ("meta", "data", "videos"):
        for path in sorted((root / part).rglob("*")):
            limit = READ.get(path.suffix)
            problem = None if limit is None else regular_problem(path, limit)
            if problem:
                problems.append(f"{path.relative_to(root)} {problem}")
    return problems


def check_files(root: Path) -> None:
    """ConfigError naming every file ``file_problems`` finds in the dataset at ``root``;
    called before anything reads the dataset."""
    problems = file_problems(root)
    if len(problems) == 1:
        raise ConfigError(f"the dataset at {root}: {problems[0]}; {REPLACE}")
    if problems:
        raise ConfigError(join_problems(f"the dataset at {root}", problems) + f"\n{REPLACE}")


def dataset_problems(root: Path) -> list[str]:
    """What keeps the dataset at ``root`` from being read whole (empty: nothing)."""
    import pyarrow.parquet as pq

    meta = root / "meta"
    problems = file_problems(root)
    if problems:
        return problems
    for name in ("info.json", "stats.json"):
        path = meta / name
        if not path.is_file():
            problems.append(f"meta/{name} is missing")
            continue
        try:
            json.loads(path.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as err:
            problems.append(f"meta/{name} is not valid JSON ({err})")
    if not (meta / "tasks.parquet").is_file():
        problems.append("meta/tasks.parquet is missing")
    if not list((meta / "episodes").rglob("*.parquet")):
        problems.append("meta/episodes/ holds no episode table")
    frames = 0
    files = sorted((root / "data").rglob("*.parquet"))
    if not files:
        problems.append("data/ holds no data files")
    for path in files:
        try:
            frames += pq.ParquetFile(path).metadata.num_rows
        except Exception as err:  # pyarrow raises several types for a damaged file
            problems.append(f"{path.relative_to(root)} is not readable parquet ({err})")
    if problems:
        return problems
    total = json.loads((meta / "info.json").read_text()).get("total_frames")
    if frames != total:
        problems.append(f"the data files hold {frames} frames, meta/info.json counts {total}")
    return problems


def stats_problems(stats: Any, names: dict[str, list[str]]) -> list[str]:
    """What is wrong with ``stats.json``'s mean and std of the features in ``names`` (feature
    -> the names of its values): missing, of the wrong length, not finite, a negative std."""
    problems = []
    for key, labels in names.items():
        entry = stats.get(key) if isinstance(stats, dict) else None
        for part in ("mean", "std"):
            try:
                values = np.asarray(entry[part], dtype=np.float64)  # type: ignore[index]
            except (KeyError, TypeError, ValueError):
                problems.append(f"meta/stats.json: {key} has no {part} of numbers")
                continue
            if values.shape != (len(labels),):
                problems.append(
                    f"meta/stats.json: {key} {part} has shape {values.shape}, want ({len(labels)},)"
                )
                continue
            bad = ~np.isfinite(values) | ((values < 0) if part == "std" else False)
            problems += [
                f"meta/stats.json: {key} {part} of {labels[i]} is {values[i]}"
                for i in np.flatnonzero(bad)
            ]
    return problems
