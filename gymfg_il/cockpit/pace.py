"""The first stage of each frame: pace the loop to the wall clock at the flight's rate (a
person's session), or not at all (the synthetic pilot flies as fast as the machine allows),
and say how long the loop period that led to this frame was (``cockpit.timing`` counts the
late ones)."""

from __future__ import annotations

import time


class Pace:
    """Frames ``period_s`` apart on the wall clock when ``realtime``; each ``wait`` returns at
    the start of a frame with the loop period that led to it (None for the first frame).

    A loop that falls more than a period behind starts again from now instead of bursting
    to catch up (the simulation slows; ``cockpit.timing`` says so). ``spin``: spin the last
    millisecond before a frame (one session on its own thread); sessions that share a
    process (``collect web``'s pilots) sleep only, since a spinning thread holds the GIL the
    others need."""

    def __init__(self, period_s: float, realtime: bool, *, spin: bool = True) -> None:
        self.period_s, self.realtime, self.spin = period_s, realtime, spin
        self._deadline: float | None = None
        self._last_start: float | None = None

    def restart(self) -> None:
        """Count the next frame's period from now (a frame that reset the aircraft, some ms
        of trimming, gives the next frame a whole period; the pilot's first answer to the new
        episode has it to arrive in)."""
        now = time.perf_counter()
        if self._deadline is not None:
            self._deadline = now
        if self._last_start is not None:
            self._last_start = now

    def wait(self) -> float | None:
        """Wait for the next frame's start (real time only); the loop period since the last."""
        if self._deadline is None:
            self._deadline = time.perf_counter()
        elif self.realtime:
            self._deadline += self.period_s
            now = time.perf_counter()
            if self._deadline < now - self.period_s:  # far behind: no catch-up burst
                self._deadline = now
            sleep_until(self._deadline, self.spin)
        start = time.perf_counter()
        period = None if self._last_start is None else start - self._last_start
        self._last_start = start
        return period


def sleep_until(deadline: float, spin: bool = True) -> None:
    """Sleep coarsely, then spin the last millisecond (sleep alone overshoots by ~0.1-1 ms);
    without ``spin``, sleep all the way."""
    remaining = deadline - time.perf_counter()
    if not spin:
        if remaining > 0:
            time.sleep(remaining)
        return
    if remaining > 0.0015:
        time.sleep(remaining - 0.001)
    while time.perf_counter() < deadline:
        pass
