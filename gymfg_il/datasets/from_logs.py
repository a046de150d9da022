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
import logging
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
from gymfg_il.datasets.episode_record import episode_columns, episode_metadata
from gymfg_il.datasets.features import WALL_TIME, check_compatible, dataset_features
from gymfg_il.datasets.gather import (
    LogOutcome,
    Unreadable,
    chosen_aircraft,
    episodes_text,
    no_logs,
    read_logs,
)
from gymfg_il.datasets.health import dataset_problems, stats_problems
from gymfg_il.datasets.provenance import metadata_columns, write_columns
from gymfg_il.datasets.verify import MARK, Checked, differences, digest
from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE, check_views, episode_frames, image_key
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode
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
    # dataset episodes that name no log (LeRobot's editing drops the records) but hold the
    # frames of a log episode: dataset index -> that episode
    matched: dict[int, EpisodeRef] = field(default_factory=dict)


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
    records: dict[EpisodeRef, dict[str, Any]],
) -> tuple[Checked, list[EpisodeRef | None]]:
    """(what keeps the dataset at ``root`` from being kept, in ``Checked.problems``: it
    cannot be read whole, or its frames or episode records differ from its logs; the log
    episode each of its episodes names).
    Features or a rate other than the logs' are the dataset's damage when the logs hold every
    episode it has (the logs are the truth), else ConfigError: another task's dataset."""
    problems = dataset_problems(root)
    if problems:
        return Checked(problems), []
    try:
        meta = lr.open_metadata(root)
    except Exception as err:  # any failure to load means: rebuild from the logs
        return Checked([f"LeRobot cannot load it ({type(err).__name__}: {err})"]), []
    if meta.episodes is None or len(meta.episodes) != meta.total_episodes:
        return Checked(["its episode table does not list every episode"]), []
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
            return Checked([f"its info.json disagrees with the logs of its episodes ({err})"]), refs
        raise
    names = {k: list(meta.features[k]["names"]) for k in ("observation.state", "action")}
    stats = stats_problems(meta.stats, names)  # train bc refuses them and sends you here
    if stats:
        return Checked(stats), refs
    return differences(root, meta, logged, refs, records), refs


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
    only = _base_order(logs, log_paths)
    chosen = chosen_aircraft(logs, callsigns)
    first_log, first = chosen[0]
    info = first_log.aircraft(first)
    views = check_views(first_log.session.get("images", []) if images is None else images)
    size = int(first_log.session.get("image_size", DEFAULT_IMAGE_SIZE))
    cameras = {image_key(v): Camera(size, size, view=v) for v in views}
    fps = first_log.spec.agent_hz
    repo_id = repo_id or f"gymfg/{info['task'].get('task', 'task')}-{info['model']}"
    offered = _offered(logs, chosen, only)
    logged = {ref: episode_columns(ep, c) for _, ep, c, ref in offered}
    records = {ref: episode_metadata(lg, ep, c) for lg, ep, c, ref in offered}
    # frames flown in real time keep their wall time in a dataset made now (not in one
    # made without the column: its features stay)
    clock = any((columns[WALL_TIME] >= 0).any() for columns in logged.values())
    features = dataset_features(info["observation_names"], views, size, clock)
    work = root.with_name(f"{root.name}.building-{time.time_ns()}")
    old = _existing(root, work, features, fps, logged, records)
    outcomes = {lg.path.name: LogOutcome(lg.path.name, damaged=bool(lg.damage)) for lg in logs}
    try:
        builder = DatasetBuilder(work, repo_id, fps, features, robot_type=info["model"])
        added = _add(builder, offered, logged, records, old, outcomes, cameras)
        builder.finalize(card_root=root)
        total = builder.meta.total_episodes
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    _swap_in(work, root)
    for name, pairs in added.twins.items():
        outcomes[name].left_out += _twin_lines(pairs)
    twins = added.twins.values()
    skipped = sum(1 for lg in logs for e in lg.episodes if not e.complete and not e.discarded)
    return BuildReport(
        added.episodes,
        added.frames,
        skipped,
        total,
        time.perf_counter() - started,
        old.aside is not None,
        _damage(logs, unreadable),
        empty,
        set(logged),
        list(outcomes.values()),
        unreadable,
        old.problems,
        old.aside,
        {t: ref for pairs in twins for ref, t in pairs if isinstance(t, int)},
    )


def _damage(logs: list[Log], unreadable: list[Unreadable]) -> list[str]:
    """ "log: what was lost and why", for the logs read and those that could not be."""
    damage = [f"{lg.path.name}: {note}" for lg in logs for note in lg.damage]
    return damage + [f"{u.path.name}: not read: {u.why}" for u in unreadable]


def _base_order(logs: list[Log], log_paths: Sequence[Path]) -> dict[str, set[tuple[int, str]]]:
    """Put a DAgger session's linked base logs first, in the base dataset's order (``logs``
    sorted in place); of each, the (episode, callsign) the base dataset took."""
    base = [ref for _, ref in base_refs({p.parent for p in log_paths}) if ref is not None]
    only: dict[str, set[tuple[int, str]]] = {}
    for ref in base:
        only.setdefault(ref.log, set()).add((ref.episode, ref.callsign))
    rank = {name: i for i, name in enumerate(dict.fromkeys(ref.log for ref in base))}
    logs.sort(key=lambda lg: (rank.get(lg.path.name, len(rank)), str(lg.path)))
    return only


def _offered(
    logs: list[Log], chosen: list[tuple[Log, str]], only: dict[str, set[tuple[int, str]]]
) -> list[tuple[Log, LoggedEpisode, str, EpisodeRef]]:
    """Every episode the logs offer, in the order a build takes them."""
    taken = {(lg.path, c) for lg, c in chosen}
    offered = []
    for lg in logs:
        wanted = only.get(lg.path.name)
        for episode in lg.complete_episodes:
            for callsign in episode.steps:  # in the order the flight lists them
                if (lg.path, callsign) in taken and (
                    wanted is None or (episode.index, callsign) in wanted
                ):
                    ref = EpisodeRef(lg.path.name, episode.index, callsign)
                    offered.append((lg, episode, callsign, ref))
    return offered


@dataclass
class _Existing:
    """What a build keeps of the dataset already at its root."""

    refs: list[EpisodeRef | None] = field(default_factory=list)  # each episode's log episode
    digests: list[str] = field(default_factory=list)  # each episode's frames
    problems: list[str] = field(default_factory=list)  # why it was set aside
    aside: Path | None = None  # where


def _existing(
    root: Path,
    work: Path,
    features: dict[str, Any],
    fps: int,
    logged: dict[EpisodeRef, dict[str, np.ndarray]],
    records: dict[EpisodeRef, dict[str, Any]],
) -> _Existing:
    """Check the dataset at ``root`` against the logs: copy it to ``work`` to build on (with
    the marks given since), or set it aside as ``<root>.broken-<time>`` to rebuild."""
    if not root.exists():
        return _Existing()
    checked, refs = _check(root, features, fps, logged, records)
    if checked.problems:
        aside = root.with_name(f"{root.name}.broken-{time.strftime('%Y%m%d-%H%M%S')}")
        root.rename(aside)
        log.warning(
            "the dataset at %s differs from its logs or cannot be read; kept it as %s and "
            "rebuilt it: %s",
            root,
            aside,
            "; ".join(checked.problems[:3]),
        )
        return _Existing(problems=checked.problems, aside=aside)
    shutil.copytree(root, work)
    write_columns(work, {MARK: checked.marks})  # marks given after the build
    return _Existing(refs, checked.digests)


@dataclass
class _Added:
    episodes: int = 0
    frames: int = 0
    # per log, its episodes left out as repeats of another's (a log episode or a dataset index)
    twins: dict[str, list[tuple[EpisodeRef, EpisodeRef | int]]] = field(default_factory=dict)


def _add(
    builder: DatasetBuilder,
    offered: list[tuple[Log, LoggedEpisode, str, EpisodeRef]],
    logged: dict[EpisodeRef, dict[str, np.ndarray]],
    records: dict[EpisodeRef, dict[str, Any]],
    old: _Existing,
    outcomes: dict[str, LogOutcome],
    cameras: dict[str, Camera],
) -> _Added:
    """Add each offered episode the dataset does not hold yet (by its log episode, or by its
    frames), saying in ``outcomes`` what became of each."""
    holder: dict[str, EpisodeRef | int] = {}  # an episode held, or held by an earlier log
    for k, (held, d) in enumerate(zip(old.refs, old.digests, strict=True)):
        holder.setdefault(d, k if held is None else held)
    present = {held for held in old.refs if held is not None}
    added = _Added()
    for lg, episode, callsign, ref in offered:
        outcome = outcomes[lg.path.name]
        columns = logged[ref]
        if ref in present:
            outcome.held.append(ref)
        elif (
            twin := holder.setdefault(digest(columns["observation.state"], columns["action"]), ref)
        ) != ref:
            added.twins.setdefault(lg.path.name, []).append((ref, twin))
            continue
        else:
            pictures = {k: episode_frames(lg, episode, callsign, c) for k, c in cameras.items()}
            task = lg.aircraft(callsign)["task_description"]
            builder.add_episode(columns, task, records[ref], pictures)
            outcome.added.append(ref)
            added.episodes += 1
            added.frames += len(columns["action"])
        outcome.seeds.append(records[ref]["seed"])
    return added


def _swap_in(work: Path, root: Path) -> None:
    """The built copy takes the dataset's place (the old one deleted only then)."""
    if root.exists():
        old = root.with_name(f"{root.name}.old-{time.time_ns()}")
        root.rename(old)
        work.rename(root)
        shutil.rmtree(old)
    else:
        work.rename(root)
    _clean_leftovers(root)


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
