"""Reading MCAP trajectory logs, finished or not (a killed session leaves no footer), damaged
or not (a bad chunk costs the episodes it held, and ``Log.damage`` says which and why)."""

from __future__ import annotations

import gc
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import orjson

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import GymFGError
from gymfg_il.files import LOG_LIMIT, NotRegularFileError, read_regular
from gymfg_il.recording.mcap_walk import Damage, magic_damage
from gymfg_il.recording.messages import Sorter, stream
from gymfg_il.recording.schemas import MARKS
from gymfg_il.recording.session import spec_of, upgrade
from gymfg_il.rollout.records import OpponentView
from gymfg_il.sim.properties import ACTION_NAMES, NAMES


class LogError(GymFGError, ValueError):
    """A file that is not a GymFG trajectory log, or is damaged beyond its first bytes."""


class EmptyLog(LogError):
    """A log file a session created but never wrote to (killed before its first fsync)."""


@dataclass
class AircraftSteps:
    """One aircraft's steps in one episode, as arrays (one row per step).

    ``state`` (the full catalogue state after each step) is decoded on first use: building a
    dataset does not need it, replay does.
    """

    observation: np.ndarray
    action: np.ndarray
    label: np.ndarray
    reward: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    intervention: np.ndarray
    # real time only: the wall clock (Unix s) when each step's input was read; -1 elsewhere
    wall_time: np.ndarray
    numbers: list[int] = field(default_factory=list, repr=False)  # the logged step numbers
    raw_states: list[Any] = field(default_factory=list, repr=False)
    _state: np.ndarray | None = field(default=None, repr=False)

    @property
    def state(self) -> np.ndarray:
        if self._state is None:
            rows = [orjson.loads(b) for b in self.raw_states]
            self._state = np.array([[r[n] for n in NAMES] for r in rows], dtype=np.float64)
        return self._state

    def __len__(self) -> int:
        return len(self.reward)


@dataclass
class LoggedEpisode:
    index: int
    start: dict[str, Any]
    end: dict[str, Any] | None = None
    discarded: bool = False
    mark: str = ""  # the pilot's own mark after it ended: success, failure, or none
    steps: dict[str, AircraftSteps] = field(default_factory=dict)
    raw_views: dict[str, list[Any]] = field(default_factory=dict, repr=False)

    @property
    def complete(self) -> bool:
        return self.end is not None and not self.discarded and not self.gaps()

    def gaps(self) -> str:
        """What is missing from an ended episode (steps or states lost to damage), or ""."""
        steps = self.end.get("steps") if self.end else None
        for callsign, s in self.steps.items():
            if s.numbers != list(range(1, len(s) + 1)):
                return f"{callsign}'s steps are not 1..{len(s)} (some were lost)"
            if len(s.raw_states) != len(s):
                return f"{callsign} has {len(s)} steps but {len(s.raw_states)} states"
        if isinstance(steps, int) and self.steps and max(map(len, self.steps.values())) != steps:
            return f"it ended after {steps} steps but {max(map(len, self.steps.values()))} remain"
        if self.end is not None and not self.steps and steps:
            return "all its steps were lost"
        return ""

    def start_of(self, callsign: str) -> dict[str, Any]:
        """``callsign``'s start: ``target``, ``initial_state`` (position) and, in logs since
        the camera, ``state`` (the whole catalogue) and the task's ``plan`` (older logs: the
        episode's target and position)."""
        aircraft = self.start.get("aircraft")
        if isinstance(aircraft, dict) and callsign in aircraft:
            return dict(aircraft[callsign])
        return {k: self.start[k] for k in ("target", "initial_state") if k in self.start}

    def views(self, team: str) -> list[OpponentView]:
        """What ``team`` saw of the other teams after each step (team runs)."""
        rows = [orjson.loads(b) for b in self.raw_views.get(team, [])]
        return [
            OpponentView(r["callsigns"], tuple(r["names"]), np.array(r["values"], np.float64))
            for r in rows
        ]


@dataclass
class Log:
    path: Path
    session: dict[str, Any]
    episodes: list[LoggedEpisode]
    finished: bool  # the file has its footer (the session closed cleanly)
    damage: list[str] = field(default_factory=list)  # what could not be read, and why

    @property
    def complete_episodes(self) -> list[LoggedEpisode]:
        return [e for e in self.episodes if e.complete]

    @property
    def spec(self) -> FlightSpec:
        """The flight spec the log was recorded with."""
        return spec_of(self.session)

    def aircraft(self, callsign: str) -> dict[str, Any]:
        """What the session record says of ``callsign``: team, model, task, observation
        names, task description."""
        try:
            return dict(self.session["aircraft"][callsign])
        except (KeyError, TypeError):
            raise LogError(f"{self.path.name} records no aircraft {callsign!r}") from None


def _steps(rows: list[dict[str, Any]], states: list[Any]) -> AircraftSteps:
    # The writer keeps the contract's action order; read values in bulk when the keys say so.
    if list(rows[0]["action"]) == list(ACTION_NAMES):
        action = [list(r["action"].values()) for r in rows]
        label = [list(r["label"].values()) for r in rows]
    else:
        action = [[r["action"][n] for n in ACTION_NAMES] for r in rows]
        label = [[r["label"][n] for n in ACTION_NAMES] for r in rows]
    return AircraftSteps(
        observation=np.array([r["observation"] for r in rows], dtype=np.float64),
        action=np.array(action, dtype=np.float64),
        label=np.array(label, dtype=np.float64),
        reward=np.array([r["reward"] for r in rows], dtype=np.float64),
        terminated=np.array([r.get("terminated", False) for r in rows], dtype=bool),
        truncated=np.array([r.get("truncated", False) for r in rows], dtype=bool),
        intervention=np.array([r.get("intervention", False) for r in rows], dtype=bool),
        wall_time=np.array([_clock(r.get("wall_time_s")) for r in rows], dtype=np.float64),
        numbers=[int(r["step"]) for r in rows],
        raw_states=states,
    )


def _clock(value: Any) -> float:
    """A logged wall-clock time, or -1 where none was logged or it is not a time (a log is
    hostile: a string, a bool, NaN or a negative number reads as none)."""
    if type(value) not in (int, float) or not math.isfinite(value) or value < 0:
        return -1.0
    return float(value)


def read_bytes(path: Path) -> bytes:
    """The bytes of the regular file at ``path``; LogError for anything else (a FIFO, whose
    open would block, a device such as /dev/zero, which never ends, a folder) or a file over
    ``LOG_LIMIT`` (``gymfg_il.files``)."""
    try:
        return read_regular(path, LOG_LIMIT, "a trajectory log is one")
    except FileNotFoundError:
        raise LogError(f"no trajectory log at {path}") from None
    except NotRegularFileError as err:
        raise LogError(str(err)) from None


def read_log(path: Path) -> Log:
    """Everything readable in ``path``: an unfinished file yields its durable part, a
    damaged one every episode the damage does not touch (``Log.damage`` says what was lost
    and why)."""
    path = Path(path)
    data = read_bytes(path)
    seen = Sorter()
    damage: list[Damage] = []
    try:
        bad_magic = magic_damage(data)
    except ValueError:
        raise LogError(
            f"{path} is not a readable GymFG trajectory log (not an MCAP file)"
        ) from None
    damage += [bad_magic] if bad_magic else []
    # Tens of thousands of small decoded messages would trigger the cyclic GC many times
    # over; none of them form cycles.
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        session, finished = stream(data, seen, damage)
    finally:
        if gc_was_enabled:
            gc.enable()
    if session is None:
        if not seen.events and not damage:
            raise EmptyLog(
                f"{path} holds no session record and no episode (a session stopped before "
                "its first write); nothing in it to keep"
            )
        raise LogError(
            f"{path} is not a readable GymFG trajectory log: its session record is lost "
            f"({'; '.join(map(str, damage)) or 'none was written'})"
        )
    episodes = _episodes(seen)
    notes = [str(d) for d in damage] + _lost(episodes, seen)
    return Log(path, upgrade(session), episodes, finished, notes)


def _episodes(seen: Sorter) -> list[LoggedEpisode]:
    episodes: dict[int, LoggedEpisode] = {}
    for ev in seen.events:
        k = ev["episode"]
        if ev["event"] == "start":
            episodes[k] = LoggedEpisode(k, ev)
        elif k in episodes and ev["event"] == "end":
            episodes[k].end = ev
        elif k in episodes and ev["event"] == "discard":
            episodes[k].discarded = True
        elif k in episodes and ev["event"] == "mark" and ev.get("mark") in MARKS:
            episodes[k].mark = str(ev["mark"])
    for (k, callsign), msgs in seen.rows.items():
        if k in episodes:
            episodes[k].steps[callsign] = _steps(msgs, seen.states.get((k, callsign), []))
    for (k, team), views in seen.views.items():
        if k in episodes:
            episodes[k].raw_views[team] = views
    return [episodes[k] for k in sorted(episodes)]


def _lost(episodes: list[LoggedEpisode], seen: Sorter) -> list[str]:
    """Episodes that damage took: ended but missing steps, never ended although later
    episodes began (the last one unended is where a session stopped, not damage), or whose
    start was lost (steps without one, or a number skipped before the last episode)."""
    notes = []
    for i, ep in enumerate(episodes):
        if ep.discarded:
            continue
        if ep.end is not None and ep.gaps():
            notes.append(f"episode {ep.index}: {ep.gaps()}; left out")
        elif ep.end is None and i < len(episodes) - 1:
            notes.append(f"episode {ep.index}: its end was lost; left out")
    started = {ep.index for ep in episodes}
    known = started | {k for k, _ in seen.rows} | {int(e.get("episode", -1)) for e in seen.events}
    for k in range(max(known, default=-1) + 1):
        if k not in started:
            notes.append(f"episode {k}: its start was lost; left out")
    return notes
