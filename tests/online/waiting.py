"""Waiting in the online tests: on conditions, with deadlines that only bound a failure
(a slow or busy machine makes a test take longer, never fail), never a fixed sleep."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any


def wait_until(condition: Callable[[], Any], what: str, timeout_s: float = 60.0) -> Any:
    """``condition()``'s first true value; AssertionError naming ``what`` after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"not within {timeout_s:g} s: {what}")
        time.sleep(0.02)


class Lines:
    """The lines a process prints on stdout, read in a thread as they come."""

    def __init__(self, proc: Any) -> None:
        self.proc = proc
        self.lines: list[str] = []
        self.ended = False
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        for raw in self.proc.stdout:
            with self._cond:
                self.lines.append(raw.decode(errors="replace").rstrip("\n"))
                self._cond.notify_all()
        with self._cond:
            self.ended = True
            self._cond.notify_all()

    def wait_for(self, text: str, quiet_s: float = 60.0) -> str:
        """The first line holding ``text``. The deadline is on silence: every line printed
        restarts it, so a long run on a slow machine passes while a hung one fails; a
        process that ends without printing ``text`` fails at once."""
        seen = 0
        with self._cond:
            while True:
                for line in self.lines[seen:]:
                    if text in line:
                        return line
                seen = len(self.lines)
                if self.ended:
                    raise AssertionError(f"ended without {text!r}:\n{self.tail()}")
                if not self._cond.wait(quiet_s) and len(self.lines) == seen:
                    raise AssertionError(f"silent for {quiet_s:g} s, no {text!r}:\n{self.tail()}")

    def tail(self, n: int = 30) -> str:
        return "\n".join(self.lines[-n:])
