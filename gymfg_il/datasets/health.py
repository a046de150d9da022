"""Whether a LeRobot dataset on disk is whole, and what is wrong with it when it is not.

LeRobot itself, given a dataset with a file missing, tries to download the rest from the Hub
(and, offline, fails with a network error that says nothing about the dataset). This looks
first: the metadata files parse, the statistics and task table are there, and the data files
are readable parquet holding every frame the metadata counts.
"""

from __future__ import annotations

import json
from pathlib import Path


def dataset_problems(root: Path) -> list[str]:
    """What keeps the dataset at ``root`` from being read whole (empty: nothing)."""
    import pyarrow.parquet as pq

    meta = root / "meta"
    problems = []
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
