"""Re-flying a recorded episode through JSBSim from its seed and actions.

The environment is rebuilt from the session record, reset with the episode's seed, and driven
with the logged (executed) actions; every state must match the log bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode


@dataclass
class ReplayResult:
    episode: int
    steps: int
    identical: bool
    max_abs_diff: float
    first_mismatch: int | None


def env_from_session(session: dict[str, object], views: list[int] | None = None) -> AircraftEnv:
    spec = session.get("env")
    if not isinstance(spec, dict):
        raise ConfigError("the log's session record has no env spec; it cannot be replayed")
    return AircraftEnv(
        spec["task"],
        spec["aircraft"],
        dynamic=bool(spec["dynamic"]),
        task_kwargs=spec.get("task_kwargs") or {},
        agent_hz=int(spec["agent_hz"]),
        sim_hz=int(spec["sim_hz"]),
        episode_time_s=float(spec["episode_time_s"]),
        views=views,
    )


def replay_episode(
    log: Log,
    episode: LoggedEpisode,
    callsign: str = "ego",
    env: AircraftEnv | None = None,
    on_step: Callable[[AircraftEnv, int], None] | None = None,
) -> ReplayResult:
    """Re-fly ``episode`` and compare every state with the log; ``on_step`` (a viewer such
    as the GUI or FlightGear) is called after each step."""
    if callsign not in episode.steps:
        raise ConfigError(f"episode {episode.index} has no steps of {callsign!r}")
    steps = episode.steps[callsign]
    own = env is None
    env = env or env_from_session(log.session)
    try:
        env.reset(seed=int(episode.start["seed"]))
        slot = env.world.slots[0]
        logged = steps.state
        worst, first = 0.0, None
        for i, action in enumerate(steps.action):
            env.step(action)
            diff = np.abs(slot.state - logged[i])
            if first is None and not np.array_equal(slot.state, logged[i]):
                first = i
            worst = max(worst, float(np.nanmax(diff)))
            if on_step is not None:
                on_step(env, i)
    finally:
        if own:
            env.close()
    return ReplayResult(episode.index, len(steps), first is None, worst, first)
