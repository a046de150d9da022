"""Recording sessions: a pilot flies seeded episodes (optionally with DART noise), an expert
labels every visited state, and every step goes to the session's MCAP log in seed order.

Episodes are flown on worker processes when asked (``workers``); the log is written by this
process as results arrive in seed order, so it is identical to a one-worker session.
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.features import check_compatible, dataset_features
from gymfg_il.datasets.provenance import metadata_columns
from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE
from gymfg_il.envs.flight import STILL_AIR, FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.recording.recorder import LOGS, new_log_path
from gymfg_il.recording.session import session_record
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.records import Episode
from gymfg_il.rollout.seeded import iter_many
from gymfg_il.tasks.verdicts import EpisodeVerdict, TrackedError
from gymfg_il.workers import Workers

DATASET = "dataset"
INVITES = "invites.json"  # a web session's invites (``collect web``: ``web.invites``)
PROBE = ".gymfg-write-check-"  # a session's check that it may write (a moment's file)
log = logging.getLogger(__name__)

__all__ = [
    "DATASET",
    "LOGS",
    "SessionResult",
    "check_appendable",
    "check_out_folder",
    "record_session",
]


def check_out_folder(out: Path) -> None:
    """``out`` must be new, empty, or a session folder (``logs/``, ``dataset/``, policies),
    in a place this process may write to (checked before anything is flown)."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        # of this thread: the sessions of a web server check the same folder at once
        probe = out / f"{PROBE}{os.getpid()}-{threading.get_ident()}"
        probe.touch()
        probe.unlink()
    except OSError as err:
        raise ConfigError(
            f"--out {out}: cannot write there ({err.strerror}); give a folder you may write to"
        ) from None
    if out.is_dir():
        foreign = sorted(
            p.name
            for p in out.iterdir()
            if p.name not in (LOGS, DATASET, INVITES)
            and not p.name.startswith(PROBE)  # another session's, checking at the same time
            and not p.name.startswith(DATASET + ".")
            and not p.name.startswith("policy-")
        )
        if foreign:
            raise ConfigError(
                f"--out {out} holds {foreign[:5]}, which are not a collection session's; give a "
                "new folder or one made by `collect` (logs/, dataset/, invites.json)"
            )


def check_appendable(
    out: Path,
    observation_names: Sequence[str],
    fps: int,
    flight: FlightSpec | None = None,
    images: Sequence[str] = (),
    image_size: int = DEFAULT_IMAGE_SIZE,
) -> None:
    """Refuse, before flying anything, to collect data the existing dataset cannot take; warn
    when it holds another flight (a policy trained on both has no single flight to fly)."""
    root = out / DATASET
    if not (root / "meta" / "info.json").is_file():
        return
    meta = lr.open_metadata(root)
    wanted = dataset_features(observation_names, images, image_size)
    check_compatible(meta.features, wanted, str(root))
    if meta.fps != fps:
        raise ConfigError(f"the dataset at {root} is at {meta.fps} fps, not {fps}")
    episodes = metadata_columns(meta)
    if flight is None or "gymfg/spec" not in episodes:
        return
    mine = flight.replace(episode_time_s=1.0)  # episode times may differ
    theirs = {FlightSpec.from_json(s).replace(episode_time_s=1.0) for s in episodes["gymfg/spec"]}
    starts = {spec.trimmed_starts for spec in theirs}
    if mine.trimmed_starts not in starts:
        raise ConfigError(
            f"the dataset at {root} holds episodes flown from "
            f"{'trimmed' if True in starts else 'untrimmed'} starts (an older dataset: trimmed "
            "starts are the default since 2026-11-25); these would start "
            f"{'trimmed' if mine.trimmed_starts else 'untrimmed'} and mix two kinds of opening "
            "in one dataset: collect into a new --out folder"
        )
    if {t.replace(**STILL_AIR) for t in theirs} - {mine.replace(**STILL_AIR)}:
        log.warning(
            "the dataset at %s holds episodes of another flight (aircraft, task, options or "
            "rate); a policy trained on it will record no single flight to be flown at",
            root,
        )
    elif theirs - {mine}:  # weather alone: the policy keeps its first episodes' (frames.flight_of)
        log.info("the dataset at %s holds episodes flown in other weather", root)


def collected(out: Path, flight: FlightSpec, source: str) -> set[tuple[int, float]]:
    """(seed, noise) of each episode of this flight and source the dataset at ``out`` holds."""
    root = out / DATASET
    if not (root / "meta" / "info.json").is_file():
        return set()
    episodes = metadata_columns(lr.open_metadata(root))
    need = ("gymfg/seed", "gymfg/spec", "gymfg/source", "gymfg/noise")
    if not set(need) <= set(episodes):
        return set()
    rows = zip(*(episodes[c] for c in need), strict=True)
    return {
        (int(seed), float(n))
        for seed, spec, src, n in rows
        if src == source and FlightSpec.from_json(spec) == flight
    }


@dataclass
class SessionResult:
    log: Path | None  # None when there was nothing to fly
    episodes: list[Episode]

    @property
    def steps(self) -> int:
        return sum(e.steps for e in self.episodes)

    @property
    def returns(self) -> list[float]:
        return [e.total_return for e in self.episodes]


def judged(episode: Episode, gusty: bool) -> dict[str, Any]:
    """A one-aircraft episode's verdict and grade as its end event stores them
    (``tasks.verdicts.EpisodeVerdict``; nothing where it is not judged: a team's episode, a
    maneuver whose judge the library cannot find)."""
    if len(episode.trajectories) != 1:
        return {}
    t = episode.solo
    task = t.start.task
    states = np.vstack([t.start.state[None], t.states])
    tracked = TrackedError.of(task)
    errors = tracked.column(t.next_observations) if tracked is not None else np.zeros(0)
    verdict = EpisodeVerdict.flown(task, states, errors, episode.dt, gusty)
    found = verdict.judge(episode.outcome if t.terminated else None)
    if found is None:
        return {}
    return {"success": found.success, "verdict": found.detail, "grade": found.grade}


def record_session(
    flight: FlightSpec,
    pilot: AgentSpec,
    expert: AgentSpec | None,
    seeds: Sequence[int],
    out: Path,
    source: str,
    noise: float = 0.0,
    workers: int | Workers = 1,
    iteration: int = 0,
    progress: Callable[[int, float], None] | None = None,
    images: Sequence[str] = (),
    image_size: int = DEFAULT_IMAGE_SIZE,
) -> SessionResult:
    """Fly one episode of ``flight`` per seed and log them to a new MCAP log under
    ``out/logs``; ``progress(i, return)`` is called once each episode is durable. ``images``:
    the camera views the dataset built from the log draws (``datasets.videos``)."""
    check_out_folder(out)
    record = session_record(
        flight, source, noise=noise, iteration=iteration, images=list(images), image_size=image_size
    )
    names = record["aircraft"]["ego"]["observation_names"]
    check_appendable(out, names, flight.agent_hz, flight, images, image_size)
    episodes: list[Episode] = []
    if not seeds:
        return SessionResult(None, episodes)
    flown = iter_many(flight, pilot, seeds, workers, expert=expert, noise=noise)
    with TrajectoryWriter(new_log_path(out, source), record) as writer:
        for i, episode in enumerate(flown):
            end = judged(episode, flight.gusty)
            writer.write_episode(episode, end, source=source, iteration=iteration)
            episodes.append(episode)
            if progress is not None:
                progress(i, episode.total_return)
    return SessionResult(writer.path, episodes)
