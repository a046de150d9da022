"""Recording a flight you drive yourself: wrap an ``OfflineEnv``, ``OnlineEnv`` or
``AircraftEnv`` and every step of every aircraft goes to an MCAP log.

    env = Recorder(OfflineEnv(opponents=[(blue, [ConstantAgent()])]), "runs/dogfight")
    team_state, opponent_states = env.reset(red, seed=0)      # the paper's loop, unchanged
    ... env.step(np.hstack(actions)) ...
    env.close()                                               # finishes the log

The log lands in ``OUT/logs/`` with the run's flight spec, every aircraft's observations,
actions, rewards, states and flags (the env's own opponents too), and what each team saw of
the others; ``collect replay OUT`` re-flies it bit for bit and ``collect recover OUT`` turns
every aircraft's trajectory into dataset episodes. Records come from the same functions the
rollout loop uses, so a recorded run and a collected one read alike.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import EnvStateError
from gymfg_il.recording.session import session_record
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.rollout.loop import observe_live, starts, step_records, team_views
from gymfg_il.rollout.records import Step, Tick, reset_record

LOGS = "logs"


def _outcome(truncated: bool, records: list[Step], info: dict[str, Any]) -> str:
    """As ``Episode.outcome`` says it: the time limit (or the server's reason for ending the
    simulation), or why the last aircraft stopped."""
    if truncated:
        return str(info.get("server_reason") or "time limit")
    reasons = [s.reason for s in records if s.reason]
    return reasons[-1] if reasons else "terminated"


def new_log_path(out: Path, tag: str = "session") -> Path:
    """A fresh log file name under ``out/logs``."""
    import os
    import time

    stamp = time.strftime("%Y%m%d-%H%M%S")
    return out / LOGS / f"{tag}-{stamp}-{os.getpid()}-{time.time_ns() % 10**6:06d}.mcap"


class Recorder:
    """Log every step of ``env`` to a new MCAP log under ``out/logs`` (see the module
    docstring). Any other attribute is the env's."""

    def __init__(self, env: Any, out: Path | str, source: str = "run", **extra: Any) -> None:
        self.env = env
        self.out = Path(out)
        self.source = source
        self.extra = extra
        self.writer: TrajectoryWriter | None = None
        self._team: Any = None
        self._done = True
        self._spec: FlightSpec | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self.env, name)

    @property
    def log(self) -> Path | None:
        """The log being written (None before the first reset)."""
        return self.writer.path if self.writer is not None else None

    def _open(self) -> TrajectoryWriter:
        world = self.env.world
        spec = FlightSpec.of_world(world)
        if self.writer is not None and spec != self._spec:
            self.writer.close()  # another team or settings: another log
            self.writer = None
        if self.writer is None:
            tasks = {s.callsign: s.task for s in world.slots}
            # an online client's world: its opponents are on the server (OnlineEnv)
            online = world.external_targets
            record = session_record(spec, self.source, tasks, online=online, **self.extra)
            self.writer = TrajectoryWriter(new_log_path(self.out, self.source), record)
            self._spec = spec
        return self.writer

    def reset(self, *args: Any, seed: int | None = None, **kwargs: Any) -> Any:
        """The env's reset; a seed is drawn when none is given (a log must say its seed)."""
        if self.writer is not None and not self._done:
            self.writer.discard_episode("reset before the episode ended")
        if seed is None:
            seed = int(np.random.default_rng().integers(2**31))
        solo = isinstance(self.env, AircraftEnv)
        if solo:
            out = self.env.reset(seed=seed, **kwargs)
        else:
            out = self.env.reset(*args, seed=seed, **kwargs)
            self._team = self.env.team
        writer = self._open()
        world = self.env.world
        options = reset_record(kwargs.get("options"), world.slots[0].callsign if solo else None)
        writer.start_episode(seed, starts(world), options, source=self.source)
        self._done = False
        return out

    def step(self, action: Any) -> Any:
        if self._done or self.writer is None:
            raise EnvStateError("call reset() before step() (and again after an episode ends)")
        world = self.env.world
        before = observe_live(world)
        out = self.env.step(action)
        if isinstance(self.env, AircraftEnv):
            _, _, terminated, truncated, info = out
            views = {}
        else:
            _, opponents, _, terminated, truncated, info = out
            names = tuple(getattr(self.env, "view", ()) or world.config.opponent_view)
            own = (self._team.name, info.get("opponent_callsigns", []), opponents)
            views = team_views(world, names, own)
        done = bool(terminated or truncated)
        records = step_records(world, before, {}, {}, done)
        self.writer.log_tick(Tick(world.steps, records, views, done, bool(truncated)))
        if done:
            self.writer.end_episode(
                outcome=_outcome(bool(truncated), records, info),
                steps=world.steps,
                interventions=0,
            )
            self._done = True
        return out

    def close(self) -> None:
        """Finish the log (an episode in flight is logged as discarded), then the env."""
        try:
            if self.writer is not None:
                self.writer.close()
        finally:
            self.env.close()
