"""The recorder stage of the cockpit session: every step goes to the session's MCAP log (the
write-ahead log every dataset is built from, ``recording.writer``) as soon as it is flown, and
what the episode flew is kept to judge it when it ends (the debrief: ``display.briefing``).

A session flown in real time also keeps each frame's wall clock (when its input was read) and
the loop periods (``cockpit.timing``): the episode's late frames, rate and jitter are stored
with it, and the window warns while frames come late.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.cockpit.timing import WARN_S, EpisodeTiming
from gymfg_il.display.briefing import Debrief, debrief_of
from gymfg_il.recording.recorder import new_log_path
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.rollout.records import Start, Tick
from gymfg_il.sim.gusts import gust_records
from gymfg_il.tasks.verdicts import EpisodeVerdict

if TYPE_CHECKING:
    from gymfg_il.cockpit.inputs.source import Remote
    from gymfg_il.sim.simulation import Simulation


class FlightLog:
    """The session's log and the episode being flown.

    Args:
        out: the session folder; the log is opened in its ``logs/`` when the first episode
            starts (a session quit before flying leaves no log).
        record: the log's session record (``recording.session.session_record``).
        task: the bound task, which judges each episode (``tasks.verdicts.EpisodeVerdict``).
        dt: seconds per agent step.
        source: who flies (``human``, ``synthetic``, ``controller+human``, ...).
        pilot_name: the pilot's name stored with each episode ("" for none).
        realtime: keep the wall clock and the timing (a person's session).
        gusty: the flight is in turbulence (the task's verdict allows for it).
        throttle: the throttle of ``last_action`` before the first step.
        sim: the aircraft's simulation, whose reset drew the episode's gusts (None: none).
        tag: the start of the log file's name (``logs/TAG-<time>-<pid>-<us>.mcap``).
    """

    def __init__(
        self,
        out: Path,
        record: dict[str, Any],
        task: Any,
        dt: float,
        *,
        source: str,
        pilot_name: str,
        realtime: bool,
        gusty: bool,
        throttle: float,
        sim: Simulation | None = None,
        tag: str = "manual",
    ) -> None:
        self.out, self.record, self.task, self.dt, self.tag = out, record, task, dt, tag
        self.source, self.pilot_name, self.realtime = source, pilot_name, realtime
        self.gusty, self.sim = gusty, sim
        self.writer: TrajectoryWriter | None = None
        self.last_action = np.array([0.0, 0.0, 0.0, throttle])  # what was flown last
        self.debrief: Debrief | None = None  # the last episode's verdict
        self.timing = EpisodeTiming(dt)
        self.steps = self.interventions = 0
        self.verdict: EpisodeVerdict | None = None  # what this episode flew
        self._return = 0.0
        self._late_at = -math.inf  # when a frame last came late

    def _writer(self) -> TrajectoryWriter:
        if self.writer is None:
            self.writer = TrajectoryWriter(new_log_path(self.out, self.tag), self.record)
        return self.writer

    def start(self, seed: int, starts: list[Start]) -> None:
        """An episode begins (the rollout was just reset with ``seed``); its start event lists
        the gusts its air will blow (``sim.gusts``), if any."""
        self.verdict = EpisodeVerdict.of(self.task, self.dt, self.gusty)  # its plan now drawn
        self.verdict.start(starts[0].state)
        self._return = 0.0
        self.debrief = None
        self.steps = self.interventions = 0
        self.timing = EpisodeTiming(self.dt)
        gusts = self.sim.gusts if self.sim is not None else ()
        blown: dict[str, Any] = {"gusts": gust_records(gusts)} if gusts else {}
        self._writer().start_episode(
            seed, starts, source=self.source, pilot=self.pilot_name, **blown
        )

    def log(
        self,
        tick: Tick,
        observation: np.ndarray,
        read_at: float,
        period: float | None,
        remote: Remote | None = None,
    ) -> str | None:
        """Log one flown step (``observation``: the pilot's next one; ``read_at``: the wall
        clock its input was read at; ``period``: the loop period that led to its frame;
        ``remote``: an input from afar's arrival, round trip and age,
        ``inputs.source.Remote``); how the episode ended if this step ended it, else None."""
        afar = None
        if self.realtime and remote is not None:
            afar = {
                "input_arrived_s": remote.arrived_s,
                "input_delay_ms": 1000.0 * remote.trip_s,
                "input_age_frames": remote.age_frames,
            }
        self._writer().log_tick(tick, read_at if self.realtime else None, afar)
        (step,) = tick.steps
        self.last_action = step.action
        assert self.verdict is not None  # start() came first
        self.verdict.add(step.state, observation)
        self._return += step.reward
        self.steps += 1
        self.interventions += int(step.intervention)
        if self.realtime and period is not None and self.timing.add(period):
            self._late_at = time.perf_counter()
        if self.realtime and remote is not None:
            self.timing.add_delay(remote.trip_s, remote.age_frames)
        if not tick.done:
            return None
        return step.reason or "terminated" if step.terminated else "time limit"

    def finish(self, outcome: str) -> int:
        """Judge and end the episode; its number in the log (what a mark marks)."""
        writer = self._writer()
        assert self.verdict is not None
        self.debrief = judged = debrief_of(self.verdict, outcome, self._return)
        writer.end_episode(
            outcome=outcome,
            steps=self.steps,
            interventions=self.interventions,
            success=judged.success,
            verdict=judged.detail,
            grade=judged.grade,
            **(self.timing.record() if self.realtime else {}),
        )
        return writer.episode

    def discard(self, reason: str) -> None:
        self._writer().discard_episode(reason)

    def mark(self, episode: int, mark: str) -> None:
        """The pilot's own verdict on an ended episode of the log."""
        self._writer().mark_episode(episode, mark)

    def late_warning(self, recording: bool) -> str:
        """The window's warning while frames come late (``cockpit.timing``), else ""."""
        if not recording or time.perf_counter() - self._late_at > WARN_S:
            return ""
        return (
            f"LATE: {self.timing.late} frame(s) came late this episode; the flight slowed "
            "(the data stays exact)"
        )

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
            self.writer = None
