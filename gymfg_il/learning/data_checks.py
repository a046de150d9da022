"""What training checks of a dataset before it trusts it.

Two kinds of damage get past ``datasets.health`` (which checks that the files are there and
the frames are readable): metadata LeRobot reads and then fails on (a truncated episode or
task table raised ArrowInvalid; ``fps`` 0 in ``info.json`` a ValueError, and where a value
was missing LeRobot turned to the Hub), and values that read fine but are not numbers (one
NaN observation, one infinite action or a NaN ``std`` in ``stats.json`` trained a policy of
NaN weights and saved it). Each problem names the file, or the episode and frame, and the fix.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.datasets.health import file_problems, stats_problems
from gymfg_il.errors import ConfigError, GymFGError, join_problems

if TYPE_CHECKING:
    from gymfg_il.learning.frames import Frames

FEATURES = ("observation.state", "action")
SHOWN = 5  # damaged frames named per column


class NonFiniteDataError(ConfigError):
    """A dataset whose frames or statistics hold NaN or infinite values."""


def meta_problems(root: Path) -> list[str]:
    """What in ``root/meta`` LeRobot would fail on: a file that is not a regular file (in
    all of the dataset: ``datasets.health.file_problems``), ``info.json``'s ``fps`` and
    features, and the episode and task tables as parquet."""
    import pyarrow.parquet as pq

    meta = root / "meta"
    problems: list[str] = file_problems(root)  # before anything opens a FIFO or a device
    if problems or not (meta / "info.json").is_file():
        return problems  # datasets.health says what is missing
    try:
        info = json.loads((meta / "info.json").read_text())
    except (OSError, UnicodeDecodeError, ValueError) as err:
        return [f"meta/info.json is not valid JSON ({err})"]
    if not isinstance(info, dict):
        return [f"meta/info.json holds a {type(info).__name__}, not an object"]
    fps = info.get("fps")
    if not (isinstance(fps, int) and not isinstance(fps, bool) and fps > 0):
        problems.append(f"meta/info.json: fps={fps!r}, want the frame rate (an integer > 0)")
    features = info.get("features")
    if not isinstance(features, dict):
        problems.append("meta/info.json: features is not an object of features")
        features = {}
    for key in FEATURES:
        feature = features.get(key)
        if not isinstance(feature, dict):
            problems.append(f"meta/info.json: no {key!r} feature")
            continue
        shape, names = feature.get("shape"), feature.get("names")
        if not (
            isinstance(shape, list)
            and len(shape) == 1
            and isinstance(names, list)
            and all(isinstance(n, str) for n in names)
            and shape[0] == len(names)
        ):
            problems.append(
                f"meta/info.json: {key} has shape {shape!r} and names {names!r}; want one "
                "name per value"
            )
    tables = [*sorted((meta / "episodes").rglob("*.parquet")), meta / "tasks.parquet"]
    for path in tables:
        if not path.is_file():
            continue  # datasets.health says what is missing
        try:
            pq.read_metadata(path)
        except Exception as err:  # pyarrow raises several types for a damaged file
            problems.append(f"{path.relative_to(root)} is not readable parquet ({err})")
    return problems


def column_problems(table: Any, episodes: Any, features: dict[str, Any]) -> list[str]:
    """The columns training reads that the data files (Arrow ``table``) or the episode table
    (``episodes``, a ``datasets.Dataset``) lack."""
    need = [*FEATURES, "episode_index", "frame_index"]
    need += ["intervention"] if "intervention" in features else []
    problems = []
    for name in need:
        if name not in table.column_names:
            problems.append(f"data/ has no {name!r} column")
            continue
        column = table.column(name).combine_chunks()
        values = column.flatten() if hasattr(column, "flatten") else column
        if column.null_count or values.null_count:
            problems.append(f"data/ column {name!r} has missing values")
    if episodes is not None:
        problems += [
            f"meta/episodes/ has no {c!r} column"
            for c in ("episode_index", "length")
            if c not in episodes.column_names
        ]
    return problems


def nonfinite_problems(frames: Frames) -> list[str]:
    """Every column of observations or actions that holds NaN or inf, naming the episodes
    and frames (the first ``SHOWN`` of them) and the values."""
    problems = []
    for key, values, names in (
        ("observation.state", frames.obs, frames.observation_names),
        ("action", frames.action, frames.action_names),
    ):
        bad = ~np.isfinite(values)
        rows = np.flatnonzero(bad.any(axis=1))
        if len(rows) == 0:
            continue
        shown = []
        for r in rows[:SHOWN]:
            cells = ", ".join(
                f"{names[c] if c < len(names) else c}={values[r, c]}"
                for c in np.flatnonzero(bad[r])
            )
            shown.append(f"episode {frames.episode[r]} frame {frames.frame[r]} ({cells})")
        more = f" and {len(rows) - SHOWN} more" if len(rows) > SHOWN else ""
        problems.append(f"{key} is not finite at {'; '.join(shown)}{more}")
    return problems


def rebuild_hint(root: Path) -> str:
    session = str(root.parent) if (root.parent / "logs").is_dir() else "SESSION_DIR"
    return f"\nRebuild it from its session's logs: python -m gymfg_il.collect recover {session}"


def opened(root: Path, open_with: Callable[[Path], Any]) -> Any:
    """``open_with(root)`` (a LeRobot reader), its failures one ``ConfigError``: LeRobot raises
    what pyarrow, ``datasets`` and the Hub client raise, and turns to the Hub when its
    metadata and files disagree."""
    try:
        return open_with(root)
    except GymFGError:
        raise  # ours already says what is wrong (an unsupported LeRobot, say)
    except Exception as err:  # pyarrow, datasets, huggingface_hub and lerobot raise many types
        text = str(err).strip()
        first = f"{type(err).__name__}: {text.splitlines()[0]}" if text else type(err).__name__
        if "offline" in type(err).__name__.lower() or "HF_HUB_OFFLINE" in text:
            first = "its metadata and files disagree, and LeRobot looked for the rest online"
        raise ConfigError(
            f"LeRobot cannot read the dataset at {root} ({first})" + rebuild_hint(root)
        ) from None


def check_trainable(frames: Frames, dataset: Path) -> None:
    """Refuse (``NonFiniteDataError``) frames or statistics that are not finite numbers."""
    names = {"observation.state": frames.observation_names, "action": frames.action_names}
    stats = {"observation.state": frames.obs_stats, "action": frames.action_stats}
    problems = stats_problems(stats, names) + nonfinite_problems(frames)
    if problems:
        raise NonFiniteDataError(
            join_problems(f"the dataset at {dataset} holds values that are not numbers", problems)
            + "\nA policy trained on them would be NaN: re-record those episodes or leave them "
            "out (and rebuild meta/stats.json: python -m gymfg_il.collect recover SESSION_DIR)"
        )
