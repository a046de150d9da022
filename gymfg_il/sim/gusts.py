"""Gusts: discrete, seeded gust events a pilot recovers from (``collect manual --gusts``).

JSBSim's turbulence (``sim.weather``) is a continuous buffeting; a gust is an event: the air
moves at up to its peak speed for a second or a few, in a "1 - cosine" shape (the discrete
gust of MIL-F-8785C and of the certification rules), and the aircraft is knocked off its
flight path and must be flown back. Each episode draws its own sequence from its seed:

| gusts | peak speed | one every (after the last ended) | each lasting |
| --- | --- | --- | --- |
| light | 5-20 ft/s | 8-16 s | 1-4 s |
| moderate | 20-35 ft/s | 6-12 s | 1-4 s |
| severe | 35-50 ft/s | 4-8 s | 1-4 s |

(the peaks are the bands of derived equivalent gust velocity that grade light, moderate and
severe turbulence). Each gust is an updraft or a downdraft, tilted from the vertical by up to
60 degrees toward a compass direction drawn at random (``TILT_DEG``): at least half of it
moves the angle of attack, and the rest pushes the aircraft sideways or along its path. The
first comes half a gap into the episode. The simulation adds the gusts to JSBSim's wind at
every JSBSim step (``atmosphere/gust-{north,east,down}-fps``, ``sim.simulation``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

# level -> (peak ft/s: low, high; gap s: low, high)
GUSTS: dict[str, tuple[float, float, float, float]] = {
    "none": (0.0, 0.0, 0.0, 0.0),
    "light": (5.0, 20.0, 8.0, 16.0),
    "moderate": (20.0, 35.0, 6.0, 12.0),
    "severe": (35.0, 50.0, 4.0, 8.0),
}
GustLevel = Literal["none", "light", "moderate", "severe"]
DURATION_S = (1.0, 4.0)  # how long a gust lasts, from calm back to calm
TILT_DEG = 60.0  # the most a gust leans from the vertical
GUST_AXES = ("north", "east", "down")  # JSBSim's atmosphere/gust-<axis>-fps


@dataclass(frozen=True)
class Gust:
    """One gust: it starts ``start_s`` seconds into the episode, lasts ``duration_s`` and
    peaks halfway at (``north_fps``, ``east_fps``, ``down_fps``), the air's velocity."""

    start_s: float
    duration_s: float
    north_fps: float
    east_fps: float
    down_fps: float

    def at(self, t: float) -> float:
        """The share of the peak blowing ``t`` seconds into the episode (0 outside it)."""
        phase = (t - self.start_s) / self.duration_s
        return 0.5 * (1.0 - math.cos(2.0 * math.pi * phase)) if 0.0 <= phase < 1.0 else 0.0

    def record(self) -> dict[str, float]:
        """As the log and the dataset keep it."""
        return asdict(self)


def draw_gusts(level: str, episode_s: float, rng: np.random.Generator) -> tuple[Gust, ...]:
    """An episode's gusts at ``level`` over ``episode_s`` seconds, drawn from ``rng``."""
    low, high, gap_low, gap_high = GUSTS[level]
    if high == 0.0:
        return ()
    gusts = []
    t = 0.5 * float(rng.uniform(gap_low, gap_high))
    while t < episode_s:
        duration = float(rng.uniform(*DURATION_S))
        peak = float(rng.uniform(low, high))
        tilt = math.radians(float(rng.uniform(0.0, TILT_DEG)))
        toward = math.radians(float(rng.uniform(0.0, 360.0)))
        up = 1.0 if rng.random() < 0.5 else -1.0  # an updraft blows up: down_fps < 0
        across = peak * math.sin(tilt)
        down = -up * peak * math.cos(tilt)
        gusts.append(Gust(t, duration, across * math.cos(toward), across * math.sin(toward), down))
        t += duration + float(rng.uniform(gap_low, gap_high))
    return tuple(gusts)


def gust_at(gusts: tuple[Gust, ...], t: float) -> tuple[float, float, float]:
    """The gusts' air velocity (north, east, down; ft/s) ``t`` seconds into the episode."""
    north = east = down = 0.0
    for gust in gusts:
        share = gust.at(t)
        if share:
            north += share * gust.north_fps
            east += share * gust.east_fps
            down += share * gust.down_fps
    return north, east, down


def gust_records(gusts: tuple[Gust, ...]) -> list[dict[str, Any]]:
    """An episode's gusts as the log's start event and the dataset keep them."""
    return [g.record() for g in gusts]
