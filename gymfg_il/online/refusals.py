"""Refused messages in the server's log, bounded: a flood of bad messages cannot flood the
log."""

from __future__ import annotations

import collections
import logging
import time

log = logging.getLogger("gymfg_il.online.server")


class RefusalLog:
    """Refused messages in the log: the first few of every ``window_s`` in full, the rest
    counted and summarised in one line when the window closes."""

    def __init__(self, full: int = 5, window_s: float = 10.0) -> None:
        self.full, self.window_s = full, window_s
        self.start = time.monotonic()
        self.logged = 0
        self.quiet: collections.Counter[str] = collections.Counter()

    def refused(self, code: str, message: str) -> None:
        self.flush()
        if self.logged < self.full:
            self.logged += 1
            log.warning("refused a message (%s): %s", code, message)
        else:
            self.quiet[code] += 1

    def flush(self, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        if now - self.start < self.window_s:
            return
        if self.quiet:
            counts = ", ".join(f"{code}: {n}" for code, n in sorted(self.quiet.items()))
            log.warning(
                "refused %d more messages in the last %.0f s (%s)",
                sum(self.quiet.values()),
                now - self.start,
                counts,
            )
        self.start, self.logged = now, 0
        self.quiet.clear()
