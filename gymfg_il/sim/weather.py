"""Weather: JSBSim's own turbulence (MIL-F-8785C Dryden spectrum) and a steady wind, seeded
per episode so that a run in turbulence reproduces bit for bit.

| turbulence | severity (probability of exceedance) | wind at 20 ft |
| --- | --- | --- |
| none | - | - |
| light | 3 (1e-2) | 15 kt |
| moderate | 4 (1e-3) | 30 kt |
| severe | 6 (1e-5) | 45 kt |

(the reference values of JSBSim's FGWinds, after the milspec's figures 7 and 9). The wind
blows from ``wind_from_deg`` (true), or from a direction drawn per episode when it is None.
Discrete gust events (``gusts``, ``sim.gusts``) are drawn per episode after the rest, so an
episode without them draws exactly what it did before they existed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.sim.gusts import GUST_AXES, GUSTS, Gust, GustLevel, draw_gusts
from gymfg_il.units import KT_TO_FPS, wrap_360

# turbulence -> (JSBSim turb-type, severity index, wind speed at 20 ft in ft/s)
TURBULENCE: dict[str, tuple[int, int, float]] = {
    "none": (0, 0, 0.0),
    "light": (3, 3, 25.0),
    "moderate": (3, 4, 50.0),
    "severe": (3, 6, 75.0),
}
Turbulence = Literal["none", "light", "moderate", "severe"]


@dataclass(frozen=True)
class Weather:
    """The air an episode is flown in (see the module docstring)."""

    turbulence: Turbulence = "none"
    wind_kt: float = 0.0
    wind_from_deg: float | None = None
    gusts: GustLevel = "none"

    def __post_init__(self) -> None:
        problems = []
        if self.turbulence not in TURBULENCE:
            problems.append(f"turbulence={self.turbulence!r}: choose {', '.join(TURBULENCE)}")
        if self.gusts not in GUSTS:
            problems.append(f"gusts={self.gusts!r}: choose {', '.join(GUSTS)}")
        speed = self.wind_kt
        if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not 0 <= speed < 200:
            problems.append(f"wind_kt={speed!r} must be a number in [0, 200) knots")
        heading = self.wind_from_deg
        if heading is not None and not (
            isinstance(heading, (int, float)) and math.isfinite(heading)
        ):
            problems.append(f"wind_from_deg={heading!r} must be a direction in degrees")
        if problems:
            raise ConfigError("weather: " + "; ".join(problems))

    @property
    def gusty(self) -> bool:
        """Whether the air is turbulent or gusty (a verdict then allows for gusts:
        ``tasks.verdicts``)."""
        return self.turbulence != "none" or self.gusts != "none"

    @property
    def calm(self) -> bool:
        return not self.gusty and not self.wind_kt

    def draw(self, rng: np.random.Generator, episode_s: float = 0.0) -> Air:
        """This episode's air (the turbulence seed, the wind's direction if it has none, the
        gusts of an episode of ``episode_s`` seconds)."""
        kind, severity, w20 = TURBULENCE[self.turbulence]
        seed = int(rng.integers(2**31)) if kind else 0
        origin = self.wind_from_deg
        if origin is None:
            origin = float(rng.uniform(0.0, 360.0)) if self.wind_kt else 0.0
        speed = self.wind_kt * KT_TO_FPS
        toward = math.radians(origin + 180.0)  # a wind from the north blows south
        north, east = speed * math.cos(toward), speed * math.sin(toward)
        gusts = draw_gusts(self.gusts, episode_s, rng)  # last: calm air draws what it did
        return Air(kind, severity, w20, seed, north, east, gusts)


@dataclass(frozen=True)
class Air:
    """One episode's air, as JSBSim is told it (``Simulation.reset`` applies it)."""

    turb_type: int = 0
    severity: int = 0
    w20_fps: float = 0.0
    seed: int = 0
    wind_north_fps: float = 0.0
    wind_east_fps: float = 0.0
    gusts: tuple[Gust, ...] = ()

    @property
    def wind(self) -> tuple[float, float]:
        return self.wind_north_fps, self.wind_east_fps

    def before_reset(self, fdm: Any) -> None:
        """Turbulence (it survives the reset) and the wind of the initial conditions (the
        reset hands it to the atmosphere); calm air clears both, and any gust left blowing
        (the simulation blows this air's gusts as it steps)."""
        fdm["atmosphere/turb-type"] = self.turb_type
        fdm["atmosphere/turbulence/milspec/severity"] = self.severity
        fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = self.w20_fps
        fdm["atmosphere/randomseed"] = self.seed
        north, east = self.wind
        fdm["ic/vw-mag-fps"] = math.hypot(north, east)
        fdm["ic/vw-dir-deg"] = wrap_360(math.degrees(math.atan2(east, north)))  # blows toward
        for axis in GUST_AXES:
            fdm[f"atmosphere/gust-{axis}-fps"] = 0.0
