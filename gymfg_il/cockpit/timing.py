"""Honest timing of a session flown in real time.

The simulation steps once per loop, so a loop that runs late slows the flight the person sees
while simulation time, and the dataset's ``timestamp`` (frame / fps), stay exact. What the
person saw is kept beside it: a frame is late when the loop period that produced it exceeds
``LATE_FACTOR`` times the nominal one; an episode counts its late frames (and is kept), the
window warns while they happen, and the episode's end event, its dataset columns
(``gymfg/late_frames``, ``gymfg/rate_hz``, ``gymfg/jitter_ms``) and the card give the rate
achieved and its jitter; each frame keeps the wall clock its input was read at (the log's
``wall_time_s``, the dataset's ``wall_time``: ``datasets.features``). Sessions that run as
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

    def add(self, seconds: float) -> bool:
        """Count one frame's loop period; whether the frame was late."""
        self.periods.append(seconds)
        late = seconds > LATE_FACTOR * self.period_s
        self.late += late
        return late

    def record(self) -> dict[str, float | int]:
        """The episode's timing as its end event stores it: late frames, the rate achieved
        (frames per wall-clock second) and the jitter (the periods' standard deviation, ms;
        both left out where no frame was flown)."""
        n = len(self.periods)
        if not n:
            return {"late_frames": 0}
        mean = sum(self.periods) / n
        spread = math.sqrt(sum((p - mean) ** 2 for p in self.periods) / n)
        return {"late_frames": self.late, "rate_hz": 1.0 / mean, "jitter_ms": 1000.0 * spread}
