"""Honest timing of a session flown in real time.

The simulation steps once per loop, so a loop that runs late slows the flight the person sees
while simulation time, and the dataset's ``timestamp`` (frame / fps), stay exact. What the
person saw is kept beside it: a frame is late when the loop period that produced it exceeds
``LATE_FACTOR`` times the nominal one; an episode counts its late frames (and is kept), the
window warns while they happen, and the episode's end event, its dataset columns
(``gymfg/late_frames``, ``gymfg/rate_hz``, ``gymfg/jitter_ms``) and the card give the rate
achieved and its jitter, and for a pilot flying from afar (``collect web``) the input's delay
(``gymfg/input_delay_ms``: p99 of the round trip from a frame sent to the input answering it,
``gymfg/input_age_frames``: p99 of the frames between them); each frame keeps the wall clock
its input was read at (the log's ``wall_time_s``, the dataset's ``wall_time``:
``datasets.features``). Sessions that run as
fast as they can (the synthetic pilot) record none of it, and stay bit-reproducible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

LATE_FACTOR = 1.5  # a loop period longer than this many nominal periods makes a frame late
WARN_S = 1.0  # how long the window warns after a late frame


@dataclass
class EpisodeTiming:
    """The loop periods of one episode's frames, against the nominal ``period_s``."""

    period_s: float
    periods: list[float] = field(default_factory=list)
    late: int = 0
    delays: list[float] = field(default_factory=list)  # an input's round trip (s), from afar
    ages: list[int] = field(default_factory=list)  # its age when flown (frames)

    def add(self, seconds: float) -> bool:
        """Count one frame's loop period; whether the frame was late."""
        self.periods.append(seconds)
        late = seconds > LATE_FACTOR * self.period_s
        self.late += late
        return late

    def add_delay(self, trip_s: float, age_frames: int) -> None:
        """Count the round trip (s) and age (frames) of the input a frame flew by."""
        self.delays.append(trip_s)
        self.ages.append(age_frames)

    def record(self) -> dict[str, float | int]:
        """The episode's timing as its end event stores it: late frames, the rate achieved
        (frames per wall-clock second) and the jitter (the periods' standard deviation, ms;
        both left out where no frame was flown); from afar, the p99 of the input's delay
        (ms) and age (frames)."""
        n = len(self.periods)
        if not n:
            return {"late_frames": 0}
        mean = sum(self.periods) / n
        spread = math.sqrt(sum((p - mean) ** 2 for p in self.periods) / n)
        out: dict[str, float | int] = {
            "late_frames": self.late,
            "rate_hz": 1.0 / mean,
            "jitter_ms": 1000.0 * spread,
        }
        if self.delays:
            out["input_delay_ms"] = 1000.0 * p99(self.delays)
            out["input_age_frames"] = int(p99(self.ages))
        return out


def p99(values: list[float] | list[int]) -> float:
    """The 99th percentile (nearest rank) of ``values`` (not empty)."""
    ordered = sorted(values)
    return float(ordered[min(len(ordered) - 1, math.ceil(0.99 * len(ordered)) - 1)])
