"""Building (and rebuilding) a LeRobot dataset from MCAP trajectory logs.

The logs are the write-ahead log: a dataset can always be rebuilt from them, also after
``kill -9``. Every build happens on a copy of the dataset; the copy replaces the original only
when it is complete, so a build that fails or is killed leaves the existing dataset as it was.
"""

from __future__ import annotations

import gc
import logging
import math
import shutil
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets.builder import DatasetBuilder
from gymfg_il.datasets.features import dataset_features
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode, read_log

log = logging.getLogger(__name__)


@dataclass
class BuildReport:
    added: int
    frames: int
    skipped_incomplete: int
    total_episodes: int
    seconds: float
    rebuilt: bool


def episode_columns(episode: LoggedEpisode, callsign: str) -> dict[str, np.ndarray]:
    """One aircraft's logged episode as dataset columns (one frame per agent step)."""
    steps = episode.steps[callsign]
    done = np.zeros(len(steps), dtype=bool)
    done[-1] = True
    return {
        "observation.state": steps.observation,
        "action": steps.label,
        "next.reward": steps.reward,
        "next.done": done,
        "intervention": steps.intervention,
    }


def episode_metadata(
    log_file: Path, episode: LoggedEpisode, session: dict[str, Any], callsign: str
) -> dict[str, Any]:
    start, end = episode.start, episode.end or {}
    target = start.get("target")
    return {
        "aircraft": str(session.get("aircraft", "")),
        "callsign": callsign,
        "task": str(session.get("task", "")),
        "target": float(target) if target is not None else math.nan,
        "seed": int(start.get("seed", -1)),
        "source": str(start.get("source", session.get("source", ""))),
        "interventions": int(episode.steps[callsign].intervention.sum()),
        "iteration": int(start.get("iteration", 0)),
        "outcome": str(end.get("outcome", "")),
        "log": log_file.name,
        "log_episode": int(episode.index),
    }


def _dataset_ok(root: Path) -> bool:
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    try:
        meta = LeRobotDatasetMetadata("gymfg/check", root=root)
        return meta.episodes is None or len(meta.episodes) == meta.total_episodes
    except Exception:  # any failure to load means: rebuild from the logs
        return False


def _present(root: Path) -> set[tuple[str, int, str]]:
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    meta = LeRobotDatasetMetadata("gymfg/check", root=root)
    if meta.episodes is None or "gymfg/log" not in meta.episodes.column_names:
        return set()
    eps = meta.episodes
    return set(zip(eps["gymfg/log"], eps["gymfg/log_episode"], eps["gymfg/callsign"], strict=True))


def build_from_logs(
    log_paths: Sequence[Path], root: Path, repo_id: str | None = None
) -> BuildReport:
    """Make the dataset at ``root`` hold every completed episode of ``log_paths``.

    Episodes already in the dataset (by log file, episode and callsign) are kept; a dataset
    that cannot be read is set aside as ``<root>.broken-<time>`` and rebuilt from the logs.
    """
    # The build allocates many short-lived objects and no cycles: keep the cyclic GC out.
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _build(log_paths, Path(root), repo_id)
    finally:
        if enabled:
            gc.enable()


def _build(log_paths: Sequence[Path], root: Path, repo_id: str | None) -> BuildReport:
    import lerobot.datasets.dataset_metadata  # noqa: F401  (its import is not build time)

    started = time.perf_counter()
    logs: list[Log] = [read_log(p) for p in sorted(log_paths)]
    if not logs:
        raise ConfigError(f"no trajectory logs to build {root} from")
    first = logs[0].session
    names = first["observation_names"]
    for lg in logs[1:]:
        if lg.session["observation_names"] != names or lg.session["agent_hz"] != first["agent_hz"]:
            raise ConfigError(
                f"{lg.path.name} records another task or rate than {logs[0].path.name}; one "
                "dataset holds one observation layout and one fps"
            )
    features = dataset_features(names)
    fps = int(first["agent_hz"])
    repo_id = repo_id or f"gymfg/{first['task']}-{first['aircraft']}"
    rebuilt = False
    work = root.with_name(f"{root.name}.building-{time.time_ns()}")
    if root.exists() and _dataset_ok(root):
        shutil.copytree(root, work)
        present = _present(work)
    else:
        if root.exists():
            aside = root.with_name(f"{root.name}.broken-{time.strftime('%Y%m%d-%H%M%S')}")
            root.rename(aside)
            log.warning(
                "the dataset at %s could not be read; kept it as %s and rebuilt it from the logs",
                root,
                aside,
            )
            rebuilt = True
        present = set()
    added = frames = skipped = 0
    try:
        builder = DatasetBuilder(work, repo_id, fps, features, robot_type=first["aircraft"])
        for lg in logs:
            skipped += sum(1 for e in lg.episodes if not e.complete and not e.discarded)
            for episode in lg.complete_episodes:
                for callsign in sorted(episode.steps):
                    if (lg.path.name, episode.index, callsign) in present:
                        continue
                    columns = episode_columns(episode, callsign)
                    builder.add_episode(
                        columns,
                        lg.session["task_description"],
                        episode_metadata(lg.path, episode, lg.session, callsign),
                    )
                    added += 1
                    frames += len(columns["action"])
        builder.finalize()
        total = builder.meta.total_episodes
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    if root.exists():
        old = root.with_name(f"{root.name}.old-{time.time_ns()}")
        root.rename(old)
        work.rename(root)
        shutil.rmtree(old)
    else:
        work.rename(root)
    return BuildReport(added, frames, skipped, total, time.perf_counter() - started, rebuilt)
