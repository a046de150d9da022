"""A LeRobot dataset in memory (``Frames``): opened with LeRobot's own ``LeRobotDataset``,
its columns taken from the Arrow table underneath in one piece each; which flight its
episodes were flown in; and the split into training and validation episodes. The training
samples are gathered from it in ``learning.batches``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.health import check_files, dataset_problems, stats_problems
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.datasets.verify import page_problems
from gymfg_il.datasets.videos import decode_camera, image_key
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, MixedTasksError, join_problems
from gymfg_il.learning.data_checks import (
    FEATURES,
    column_problems,
    meta_problems,
    opened,
    rebuild_hint,
)
from gymfg_il.learning.frames import Frames, flight_of, observed_names


def check_tasks(episodes: dict[str, list[Any]], mixed_tasks: bool = False) -> None:
    """Refuse (``MixedTasksError``, naming the episodes of each task) a dataset whose episodes
    (``gymfg/*`` columns) were flown in different tasks: ``observation.state[k]`` would mean
    one variable in some episodes and another in the rest, or the same inputs would ask for
    different behaviours. ``mixed_tasks`` trains one policy across tasks on purpose, allowed
    only where every task observes the same names (altitude with altitude-dynamic, say).
    Datasets without the columns (older, or edited by LeRobot's tools) are not checked."""
    tasks = episodes.get("gymfg/task")
    if not tasks:
        return
    ids = episodes.get("episode_index") or list(range(len(tasks)))
    specs = episodes.get("gymfg/spec") or [None] * len(tasks)
    callsigns = episodes.get("gymfg/callsign") or ["ego"] * len(tasks)
    cache: dict[tuple[str, str], tuple[str, ...] | None] = {}
    groups: dict[tuple[str, tuple[str, ...] | None], list[int]] = {}
    for index, task, spec, callsign in zip(ids, tasks, specs, callsigns, strict=True):
        key = (str(spec), str(callsign))
        if key not in cache:
            cache[key] = observed_names(spec, callsign) if spec else None
        groups.setdefault((str(task), cache[key]), []).append(int(index))
    names = {n for _, n in groups if n is not None}
    if len({t for t, _ in groups}) <= 1 and len(names) <= 1:
        return
    if len(names) <= 1 and mixed_tasks:
        return

    def episodes_text(ids: list[int]) -> str:
        shown = ", ".join(str(i) for i in ids[:10])
        return shown + (f", ... ({len(ids)} in all)" if len(ids) > 10 else "")

    lines = []
    for (task, observed), members in sorted(groups.items(), key=lambda g: g[1][0]):
        what = "observation unknown" if observed is None else f"observes {', '.join(observed)}"
        lines.append(f"task {task!r} ({what}): episodes {episodes_text(members)}")
    if len(names) > 1:
        raise MixedTasksError(
            join_problems(
                "the dataset's episodes come from tasks that observe different variables "
                "(the same observation.state column means another variable in each group); "
                "train on one task's episodes: collect or rebuild one dataset per task "
                "(--mixed-tasks cannot help: it needs the same observation names)",
                lines,
            )
        )
    raise MixedTasksError(
        join_problems(
            "the dataset's episodes come from different tasks; pass --mixed-tasks to train "
            "one policy across them on purpose (they observe the same variables), or train "
            "on one task's episodes",
            lines,
        )
    )


def dataset_flight(root: Path) -> tuple[FlightSpec | None, str, dict[str, Any]]:
    """The flight of the dataset at ``root`` (``flight_of``), without loading its frames;
    also its ``fps`` and ``observation_names``."""
    meta = opened(Path(root), lr.open_metadata)
    spec, why = flight_of(metadata_columns(meta))
    found = {
        "fps": int(meta.fps),
        "observation_names": list(meta.features["observation.state"]["names"]),
    }
    return spec, why, found


def _column(table: Any, name: str) -> np.ndarray:
    import pyarrow as pa

    col = table.column(name).combine_chunks()
    if pa.types.is_fixed_size_list(col.type):
        flat = col.flatten().to_numpy(zero_copy_only=False)
        return flat.reshape(len(col), col.type.list_size)
    if pa.types.is_list(col.type) or pa.types.is_large_list(col.type):
        return np.stack(col.to_numpy(zero_copy_only=False))
    return col.to_numpy(zero_copy_only=False)


def load_frames(root: Path, camera: str | None = None) -> Frames:
    """Open the LeRobot dataset at ``root`` and take its frames into memory (``camera``:
    with that view's frames, decoded, ``observation.images.<camera>``)."""
    root = Path(root)
    if not (root / "meta").is_dir() and (root / "dataset" / "meta").is_dir():
        root = root / "dataset"  # a session folder: its dataset is inside
    check_files(root)  # a FIFO or a device in a file's place is named, not read
    if not (root / "meta" / "info.json").is_file():
        session = next((f for f in (root, root.parent) if any(f.glob("logs/*.mcap"))), None)
        raise ConfigError(
            f"no LeRobot dataset at {root} (no meta/info.json); "
            + (
                f"its session's logs are in {session / 'logs'} (a session killed before its "
                f"dataset was written?): build it with python -m gymfg_il.collect recover "
                f"{session}"
                if session is not None
                else "collect one with `python -m gymfg_il.collect autopilot --out DIR` and "
                "pass DIR/dataset"
            )
        )
    problems = meta_problems(root) or dataset_problems(root)
    if problems:
        raise ConfigError(
            join_problems(f"the dataset at {root} is incomplete", problems) + rebuild_hint(root)
        )
    ds = opened(root, lr.open_dataset)
    features = ds.meta.features
    table = ds.hf_dataset.data.table
    stats = ds.meta.stats
    problems = column_problems(table, ds.meta.episodes, features)
    problems += page_problems(root, features)  # damage LeRobot's reader takes as numbers
    problems += stats_problems(stats, {k: list(features[k]["names"]) for k in FEATURES})
    if problems:
        raise ConfigError(
            join_problems(f"the dataset at {root} is damaged", problems) + rebuild_hint(root)
        )
    episodes = metadata_columns(ds.meta)
    if ds.meta.episodes is not None:
        for name in ("episode_index", "length"):
            episodes[name] = list(ds.meta.episodes[name])
        _check_episode_index(table, episodes["episode_index"], root)
    return Frames(
        obs=_column(table, "observation.state").astype(np.float32),
        action=_column(table, "action").astype(np.float32),
        episode=_column(table, "episode_index").astype(np.int64),
        frame=_column(table, "frame_index").astype(np.int64),
        observation_names=list(features["observation.state"]["names"]),
        action_names=list(features["action"]["names"]),
        fps=int(ds.meta.fps),
        obs_stats={k: np.asarray(stats["observation.state"][k]) for k in ("mean", "std")},
        action_stats={k: np.asarray(stats["action"][k]) for k in ("mean", "std")},
        episodes=episodes,
        intervention=(
            _column(table, "intervention").astype(bool).reshape(-1)
            if "intervention" in features
            else None
        ),
        images=None if camera is None else decode_camera(root, image_key(camera), ds.meta),
        camera=camera,
    )


def _check_episode_index(table: Any, listed: list[Any], root: Path) -> None:
    """The episode table lists each episode of the data files once, in order (a rewritten
    ``episode_index`` would attach one episode's record to another's frames)."""
    held = np.unique(_column(table, "episode_index"))
    if [int(i) for i in listed] != list(range(len(listed))) or not np.isin(held, listed).all():
        raise ConfigError(
            f"the dataset at {root} is damaged: meta/episodes lists episode_index "
            f"{[int(i) for i in listed][:8]}..., the data files hold episodes "
            f"{held[:8].tolist()}...; want 0, 1, 2, ... in both" + rebuild_hint(root)
        )


def split_by_episode(
    frames: Frames, val_fraction: float, seed: int
) -> tuple[Frames, Frames | None]:
    """Hold out whole episodes for validation (never frames of a training episode): the
    ``val_fraction`` of them rounded down, at most all but one, and none where that is less
    than one episode (from 5 episodes at 0.1, every episode trains)."""
    if not 0.0 <= val_fraction < 1.0:
        raise ConfigError(f"val_fraction={val_fraction} must lie in [0, 1)")
    ids = np.unique(frames.episode)
    # the 1e-9: a product such as 100 x 0.29 = 28.999999999999996 still holds out 29
    n_val = min(math.floor(len(ids) * val_fraction + 1e-9), len(ids) - 1)
    if n_val <= 0:
        return frames, None
    rng = np.random.default_rng(seed)
    val = rng.choice(ids, n_val, replace=False)
    return frames.select(np.setdiff1d(ids, val)), frames.select(val)
