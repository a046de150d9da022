"""Building (and rebuilding) a LeRobot dataset from MCAP trajectory logs.

The logs are the write-ahead log: a dataset can always be rebuilt from them, also after
``kill -9``. Every build happens on a copy of the dataset; the copy replaces the original only
when it is complete, so a build that fails or is killed leaves the existing dataset as it was.
"""

from __future__ import annotations

import gc
import json
import logging
import math
import shutil
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.builder import DatasetBuilder
from gymfg_il.datasets.episode_logs import EpisodeRef, base_refs
from gymfg_il.datasets.features import dataset_features
from gymfg_il.datasets.health import dataset_problems
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE, check_views, episode_frames, image_key
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import EmptyLog, Log, LoggedEpisode, read_log
from gymfg_il.viz.camera import Camera

log = logging.getLogger(__name__)


@dataclass
class BuildReport:
    added: int
    frames: int
    skipped_incomplete: int
    total_episodes: int
    seconds: float
    rebuilt: bool
    damage: list[str] = field(default_factory=list)  # "log: what was lost and why"
    skipped_empty: list[str] = field(default_factory=list)  # logs never written to
    # the completed episodes of the logs a dataset may take (``episode_logs.unrebuildable``)
    logged: set[EpisodeRef] = field(default_factory=set)


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


def target_record(task: dict[str, Any], target: float | None) -> dict[str, Any]:
    """How an episode's target is kept: ``target`` the fixed target (NaN where it moves or
    the task has none), ``target_kind`` static, dynamic or none, and for a moving target
    ``target_plan`` (JSON): the variable, where the target starts, how it moves (waypoints
    drawn from ``target_range`` every ``hold_s`` s, approached at ``rate`` units/s; offsets
    from the start value when ``relative``). The schedule itself follows from the seed."""
    if task.get("dynamic"):
        keys = ("variable", "relative", "target_range", "fixed_target", "rate", "hold_s")
        plan: dict[str, Any] = {"start": None if target is None else float(target)}
        plan |= {k: task[k] for k in keys if k in task}
        return {"target": math.nan, "target_kind": "dynamic", "target_plan": json.dumps(plan)}
    if target is None:
        return {"target": math.nan, "target_kind": "none", "target_plan": ""}
    return {"target": float(target), "target_kind": "static", "target_plan": ""}


def episode_metadata(log: Log, episode: LoggedEpisode, callsign: str) -> dict[str, Any]:
    """The ``gymfg/*`` columns of one aircraft's episode: where it comes from and what was
    flown (``spec``: the flight spec, JSON; ``target``: ``target_record``)."""
    start, end = episode.start, episode.end or {}
    target = episode.start_of(callsign).get("target")
    info = log.aircraft(callsign)
    task = info.get("task", {}).get("task", "")
    return {
        "aircraft": str(info.get("model", "")),
        "callsign": callsign,
        "team": str(info.get("team", "")),
        "task": str(task),
        **target_record(info.get("task", {}), target),
        "seed": int(start.get("seed", -1)),
        "source": str(start.get("source", log.session.get("source", ""))),
        "noise": float(log.session.get("noise", 0.0)),
        "interventions": int(episode.steps[callsign].intervention.sum()),
        "iteration": int(start.get("iteration", 0)),
        "outcome": str(end.get("outcome", "")),
        "log": log.path.name,
        "log_episode": int(episode.index),
        "spec": log.spec.to_json(),
        "jsbsim": str(log.session.get("versions", {}).get("jsbsim", "")),
    }


def _dataset_ok(root: Path) -> bool:
    """Whether the dataset at ``root`` is whole (``health.dataset_problems``) and its
    metadata loads with LeRobot."""
    if dataset_problems(root):
        return False
    try:
        meta = lr.open_metadata(root)
        return meta.episodes is None or len(meta.episodes) == meta.total_episodes
    except Exception:  # any failure to load means: rebuild from the logs
        return False


def _clean_leftovers(root: Path) -> None:
    """Copies an interrupted build left beside the dataset (the good one is in place now)."""
    for pattern in (f"{root.name}.building-*", f"{root.name}.old-*"):
        for leftover in root.parent.glob(pattern):
            shutil.rmtree(leftover, ignore_errors=True)


def _present(root: Path) -> set[tuple[str, int, str]]:
    eps = metadata_columns(lr.open_metadata(root))
    if "gymfg/log" not in eps:
        return set()
    return set(zip(eps["gymfg/log"], eps["gymfg/log_episode"], eps["gymfg/callsign"], strict=True))


def _chosen(logs: list[Log], callsigns: Sequence[str] | None) -> list[tuple[Log, str]]:
    """(log, callsign) of every aircraft to take, checked to share one layout and rate."""
    chosen = [
        (lg, c) for lg in logs for c in lg.session.get("callsigns", [])
        if callsigns is None or c in callsigns
    ]  # fmt: skip
    if not chosen:
        raise ConfigError(f"the logs hold no aircraft {list(callsigns or [])}")
    first_log, first = chosen[0]
    names = first_log.aircraft(first)["observation_names"]
    fps = first_log.spec.agent_hz
    for lg, c in chosen[1:]:
        if lg.aircraft(c)["observation_names"] != names:
            raise ConfigError(
                f"{c!r} in {lg.path.name} observes other variables than {first!r} in "
                f"{first_log.path.name}; one dataset holds one observation layout: build one "
                "per task (choose the aircraft with callsigns=, `collect recover --callsign`)"
            )
        if lg.spec.agent_hz != fps:
            raise ConfigError(
                f"{lg.path.name} records another rate ({lg.spec.agent_hz} Hz) than "
                f"{first_log.path.name} ({fps} Hz); one dataset holds one fps"
            )
    return chosen


def build_from_logs(
    log_paths: Sequence[Path],
    root: Path,
    repo_id: str | None = None,
    callsigns: Sequence[str] | None = None,
    images: Sequence[str] | None = None,
) -> BuildReport:
    """Make the dataset at ``root`` hold every completed episode of ``log_paths``: one
    dataset episode per aircraft and logged episode (``callsigns``: only these aircraft).
    ``images``: camera views to draw as video features (default: what the session asked for,
    its record's ``images``; ``datasets.videos``).

    Episodes already in the dataset (by log file, episode and callsign) are kept; a dataset
    that cannot be read is set aside as ``<root>.broken-<time>`` and rebuilt from the logs.
    Of a log a DAgger session linked in from its base dataset, only the base episodes are
    taken, first and in the base dataset's order (``datasets.episode_logs``).
    """
    # The build allocates many short-lived objects and no cycles: keep the cyclic GC out.
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _build(log_paths, Path(root), repo_id, callsigns, images)
    finally:
        if enabled:
            gc.enable()


def _build(
    log_paths: Sequence[Path],
    root: Path,
    repo_id: str | None,
    callsigns: Sequence[str] | None,
    images: Sequence[str] | None,
) -> BuildReport:
    lr.load()  # LeRobot's import is not build time
    started = time.perf_counter()
    logs: list[Log] = []
    empty: list[str] = []
    for path in sorted(log_paths):
        try:
            logs.append(read_log(path))
        except EmptyLog:
            log.warning("skipped %s: a session stopped before writing anything to it", path)
            empty.append(path.name)
    if not logs:
        raise ConfigError(f"no trajectory logs to build {root} from")
    # a DAgger session's linked base logs: only the base episodes, first, in the base's order
    base = [ref for _, ref in base_refs({p.parent for p in log_paths}) if ref is not None]
    only: dict[str, set[tuple[int, str]]] = {}
    for ref in base:
        only.setdefault(ref.log, set()).add((ref.episode, ref.callsign))
    rank = {name: i for i, name in enumerate(dict.fromkeys(ref.log for ref in base))}
    logs.sort(key=lambda lg: (rank.get(lg.path.name, len(rank)), str(lg.path)))
    chosen = _chosen(logs, callsigns)
    first_log, first = chosen[0]
    info = first_log.aircraft(first)
    views = check_views(first_log.session.get("images", []) if images is None else images)
    size = int(first_log.session.get("image_size", DEFAULT_IMAGE_SIZE))
    cameras = {image_key(v): Camera(size, size, view=v) for v in views}
    features = dataset_features(info["observation_names"], views, size)
    fps = first_log.spec.agent_hz
    label = info["task"].get("task", "task")
    repo_id = repo_id or f"gymfg/{label}-{info['model']}"
    taken = {(lg.path, c) for lg, c in chosen}
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
    logged: set[EpisodeRef] = set()
    try:
        builder = DatasetBuilder(work, repo_id, fps, features, robot_type=info["model"])
        for lg in logs:
            skipped += sum(1 for e in lg.episodes if not e.complete and not e.discarded)
            for episode in lg.complete_episodes:
                for callsign in episode.steps:  # in the order the flight lists them
                    if (lg.path, callsign) not in taken:
                        continue
                    wanted = only.get(lg.path.name)
                    if wanted is not None and (episode.index, callsign) not in wanted:
                        continue
                    logged.add(EpisodeRef(lg.path.name, episode.index, callsign))
                    if (lg.path.name, episode.index, callsign) in present:
                        continue
                    columns = episode_columns(episode, callsign)
                    pictures = {
                        key: episode_frames(lg, episode, callsign, camera)
                        for key, camera in cameras.items()
                    }
                    builder.add_episode(
                        columns,
                        lg.aircraft(callsign)["task_description"],
                        episode_metadata(lg, episode, callsign),
                        pictures,
                    )
                    added += 1
                    frames += len(columns["action"])
        builder.finalize(card_root=root)
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
    _clean_leftovers(root)
    damage = [f"{lg.path.name}: {note}" for lg in logs for note in lg.damage]
    seconds = time.perf_counter() - started
    return BuildReport(added, frames, skipped, total, seconds, rebuilt, damage, empty, logged)
