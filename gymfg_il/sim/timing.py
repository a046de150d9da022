"""Simulation and agent rates: the agent rate must divide the JSBSim rate exactly."""

from __future__ import annotations

import math

from gymfg_il.errors import ConfigError, RateError

DEFAULT_SIM_HZ = 120
DEFAULT_AGENT_HZ = 10
MAX_EPISODE_S = 86_400.0  # a day: longer is a typo (1e308 s overflowed into a traceback)


def substeps(sim_hz: int, agent_hz: int) -> int:
    """JSBSim steps per agent step; a rate that does not divide is rejected, never truncated."""
    for name, value in (("sim_hz", sim_hz), ("agent_hz", agent_hz)):
        if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
            raise RateError(f"{name} must be a positive integer (Hz), got {value!r}")
    if sim_hz % agent_hz:
        divisors = [d for d in range(1, sim_hz + 1) if sim_hz % d == 0]
        raise RateError(
            f"agent_hz={agent_hz} does not divide sim_hz={sim_hz} exactly, so steps would drift; "
            f"choose agent_hz from {divisors} or change sim_hz"
        )
    return sim_hz // agent_hz


def episode_steps(episode_time_s: float, agent_hz: int) -> int:
    """Agent steps in an episode of ``episode_time_s`` seconds (must be a whole number)."""
    if not (math.isfinite(episode_time_s) and 0 < episode_time_s <= MAX_EPISODE_S):
        raise ConfigError(
            f"episode_time_s={episode_time_s!r}: want seconds > 0 and at most "
            f"{MAX_EPISODE_S:g} (a day)"
        )
    steps = episode_time_s * agent_hz
    if steps < 1 or abs(steps - round(steps)) > 1e-9:
        raise RateError(
            f"episode_time_s={episode_time_s} at agent_hz={agent_hz} gives {steps:g} steps; "
            "choose an episode time that is a whole number of agent steps"
        )
    return round(steps)
