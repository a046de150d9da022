"""Building (and rebuilding) a LeRobot dataset from MCAP trajectory logs.

The logs are the write-ahead log: a dataset can always be rebuilt from them, also after
``kill -9``. Every build happens on a copy of the dataset; the copy replaces the original only
when it is complete, so a build that fails or is killed leaves the existing dataset as it was.

The logs are the truth: an existing dataset is checked against them first (``verify``: every
frame of every episode, its features and rate); one that cannot be read, or differs, is set
aside as ``<root>.broken-<time>`` and rebuilt. An episode is taken once, however many logs
hold it (a log copied under another name): by its frames.
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
from gymfg_il.datasets.features import WALL_TIME, check_compatible, dataset_features
from gymfg_il.datasets.gather import (
    LogOutcome,
    Unreadable,
    chosen_aircraft,
    episodes_text,
    no_logs,
    read_logs,
)
from gymfg_il.datasets.health import dataset_problems
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.datasets.verify import differences, digest
from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE, check_views, episode_frames, image_key
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode
from gymfg_il.tasks.grades import rank
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
    logs: list[LogOutcome] = field(default_factory=list)  # what became of each log read
    unreadable: list[Unreadable] = field(default_factory=list)  # files that are no log
    differences: list[str] = field(default_factory=list)  # why the old dataset was set aside
    aside: Path | None = None  # where it was kept


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
        WALL_TIME: _since_first(steps.wall_time),
    }


def _since_first(clock: np.ndarray) -> np.ndarray:
    """Wall-clock seconds since the episode's first frame (where the log kept a time, else
    -1): LeRobot loads floats as float32, which would round Unix seconds to minutes."""
    if clock[0] < 0:
        return np.full_like(clock, -1.0)
    return np.where(clock >= 0, clock - clock[0], -1.0)


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
    flown (``spec``: the flight spec, JSON; ``target``: ``target_record``), who flew it and
    how it went (``pilot``; ``success``: the task's verdict, 1 or 0, -1 where it was not
    judged, with ``verdict`` in words; ``grade``: the task's (``tasks.grades``), or "";
    ``mark``: the pilot's own, or "")."""
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
        "pilot": _text(start.get("pilot")),
        "success": _verdict(end.get("success")),
        "verdict": _text(end.get("verdict")),
        "grade": str(end["grade"]) if rank(end.get("grade")) >= 0 else "",
        **_timing(end),
        "wall_start": float(episode.steps[callsign].wall_time[0]),  # Unix s, or -1
        "mark": episode.mark,
        "log": log.path.name,
        "log_episode": int(episode.index),
        "spec": log.spec.to_json(),
        "jsbsim": str(log.session.get("versions", {}).get("jsbsim", "")),
    }


def _timing(end: dict[str, Any]) -> dict[str, Any]:
    """A real-time episode's timing (``collectors.timing``): late frames, rate and jitter,
    each -1 where the session ran as fast as it could or the log holds none."""
    late = end.get("late_frames")
    out: dict[str, Any] = {"late_frames": late if type(late) is int and late >= 0 else -1}
    for key in ("rate_hz", "jitter_ms"):
        value = end.get(key)
        number = float(value) if isinstance(value, (int, float)) else math.nan  # a bool too
        out[key] = number if math.isfinite(number) and number >= 0 else -1.0
    return out


def _verdict(success: Any) -> int:
    """A logged verdict as its column holds it: 1, 0, or -1 where none was logged."""
    return 1 if success is True else 0 if success is False else -1


def _text(value: Any, limit: int = 200) -> str:
    """A logged string as a column holds it (a log is hostile: anything else is "")."""
    return value[:limit] if isinstance(value, str) else ""


def _clean_leftovers(root: Path) -> None:
    """Copies an interrupted build left beside the dataset (the good one is in place now)."""
    for pattern in (f"{root.name}.building-*", f"{root.name}.old-*"):
        for leftover in root.parent.glob(pattern):
            shutil.rmtree(leftover, ignore_errors=True)


def _refs(meta: Any) -> list[EpisodeRef | None]:
    """The log episode each dataset episode names (None: it names none)."""
    eps = metadata_columns(meta)
    if not all(f"gymfg/{k}" in eps for k in ("log", "log_episode", "callsign")):
        return [None] * meta.total_episodes
    return [
        EpisodeRef(str(name), int(k), str(c))
        for name, k, c in zip(
            eps["gymfg/log"], eps["gymfg/log_episode"], eps["gymfg/callsign"], strict=True
        )
    ]


def _check(
    root: Path,
    features: dict[str, Any],
    fps: int,
    logged: dict[EpisodeRef, dict[str, np.ndarray]],
) -> tuple[list[str], list[EpisodeRef | None], list[str]]:
    """(what keeps the dataset at ``root`` from being kept: it cannot be read whole, or it
    differs from its logs; the log episode each of its episodes names; their digests).
    Features or a rate other than the logs' are the dataset's damage when the logs hold every
    episode it has (the logs are the truth), else ConfigError: another task's dataset."""
    problems = dataset_problems(root)
    if problems:
        return problems, [], []
    try:
        meta = lr.open_metadata(root)
    except Exception as err:  # any failure to load means: rebuild from the logs
        return [f"LeRobot cannot load it ({type(err).__name__}: {err})"], [], []
    if meta.episodes is None or len(meta.episodes) != meta.total_episodes:
        return ["its episode table does not list every episode"], [], []
    refs = _refs(meta)
    try:
        check_compatible(meta.features, features, str(root))
        if meta.fps != fps:
            raise ConfigError(
                f"cannot append to the dataset at {root}: it was recorded at {meta.fps} fps, "
                f"the new data at {fps}; use the same agent rate or another folder"
            )
    except ConfigError as err:
        if refs and all(ref in logged for ref in refs):
            return [f"its info.json disagrees with the logs of its episodes ({err})"], refs, []
        raise
    problems, digests = differences(root, meta, logged, refs)
    return problems, refs, digests


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
    logs, empty, unreadable = read_logs(log_paths)
    if not logs:
        raise no_logs(root, unreadable)
    # a DAgger session's linked base logs: only the base episodes, first, in the base's order
    base = [ref for _, ref in base_refs({p.parent for p in log_paths}) if ref is not None]
    only: dict[str, set[tuple[int, str]]] = {}
    for ref in base:
        only.setdefault(ref.log, set()).add((ref.episode, ref.callsign))
    rank = {name: i for i, name in enumerate(dict.fromkeys(ref.log for ref in base))}
    logs.sort(key=lambda lg: (rank.get(lg.path.name, len(rank)), str(lg.path)))
    chosen = chosen_aircraft(logs, callsigns)
    first_log, first = chosen[0]
    info = first_log.aircraft(first)
    views = check_views(first_log.session.get("images", []) if images is None else images)
    size = int(first_log.session.get("image_size", DEFAULT_IMAGE_SIZE))
    cameras = {image_key(v): Camera(size, size, view=v) for v in views}
    fps = first_log.spec.agent_hz
    label = info["task"].get("task", "task")
    repo_id = repo_id or f"gymfg/{label}-{info['model']}"
    # every episode the logs offer, in the order a build takes them
    taken = {(lg.path, c) for lg, c in chosen}
    offered: list[tuple[Log, LoggedEpisode, str, EpisodeRef]] = []
    for lg in logs:
        wanted = only.get(lg.path.name)
        for episode in lg.complete_episodes:
            for callsign in episode.steps:  # in the order the flight lists them
                if (lg.path, callsign) in taken and (
                    wanted is None or (episode.index, callsign) in wanted
                ):
                    offered.append(
                        (lg, episode, callsign, EpisodeRef(lg.path.name, episode.index, callsign))
                    )
    logged = {ref: episode_columns(ep, c) for _, ep, c, ref in offered}
    # frames flown in real time keep their wall time in a dataset made now (not in one
    # made without the column: its features stay)
    clock = any((columns[WALL_TIME] >= 0).any() for columns in logged.values())
    features = dataset_features(info["observation_names"], views, size, clock)
    work = root.with_name(f"{root.name}.building-{time.time_ns()}")
    found: list[str] = []
    refs: list[EpisodeRef | None] = []
    digests: list[str] = []
    aside = None
    if root.exists():
        found, refs, digests = _check(root, features, fps, logged)
        if found:
            aside = root.with_name(f"{root.name}.broken-{time.strftime('%Y%m%d-%H%M%S')}")
            root.rename(aside)
            log.warning(
                "the dataset at %s differs from its logs or cannot be read; kept it as "
                "%s and rebuilt it: %s",
                root,
                aside,
                "; ".join(found[:3]),
            )
            refs, digests = [], []
        else:
            shutil.copytree(root, work)
    outcomes = {lg.path.name: LogOutcome(lg.path.name, damaged=bool(lg.damage)) for lg in logs}
    # an episode already held, or held by an earlier log: by its frames
    holder: dict[str, EpisodeRef | int] = {}
    for k, (held, d) in enumerate(zip(refs, digests, strict=True)):
        holder.setdefault(d, k if held is None else held)
    present = {held for held in refs if held is not None}
    twins: dict[str, list[tuple[EpisodeRef, EpisodeRef | int]]] = {}
    added = frames = 0
    try:
        builder = DatasetBuilder(work, repo_id, fps, features, robot_type=info["model"])
        for lg, episode, callsign, ref in offered:
            outcome = outcomes[lg.path.name]
            if ref in present:
                outcome.held.append(ref)
                continue
            columns = logged[ref]
            twin = holder.setdefault(digest(columns["observation.state"], columns["action"]), ref)
            if twin != ref:
                twins.setdefault(lg.path.name, []).append((ref, twin))
                continue
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
            outcome.added.append(ref)
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
    for name, pairs in twins.items():
        outcomes[name].left_out += _twin_lines(pairs)
    skipped = sum(1 for lg in logs for e in lg.episodes if not e.complete and not e.discarded)
    damage = [f"{lg.path.name}: {note}" for lg in logs for note in lg.damage]
    damage += [f"{u.path.name}: not read: {u.why}" for u in unreadable]
    return BuildReport(
        added,
        frames,
        skipped,
        total,
        time.perf_counter() - started,
        aside is not None,
        damage,
        empty,
        set(logged),
        list(outcomes.values()),
        unreadable,
        found,
        aside,
    )


def _twin_lines(pairs: list[tuple[EpisodeRef, EpisodeRef | int]]) -> list[str]:
    """One line per log (or dataset) whose episodes these repeat."""
    by: dict[str, list[tuple[EpisodeRef, EpisodeRef | int]]] = {}
    for ref, twin in pairs:
        by.setdefault(twin.log if isinstance(twin, EpisodeRef) else "", []).append((ref, twin))
    lines = []
    for name, group in by.items():
        mine = episodes_text(ref for ref, _ in group)
        if name:
            theirs = episodes_text(t for _, t in group if isinstance(t, EpisodeRef))
            lines.append(f"episodes {mine}: the same episodes as {name} ({theirs})")
        else:
            held = ", ".join(str(t) for _, t in group)
            lines.append(f"episodes {mine}: the same episodes as dataset episodes {held}")
    return lines
