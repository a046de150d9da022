"""Keeping a session's dataset up to date without stalling the real-time loop.

``python -m gymfg_il.collectors.updater OUT`` is the helper process: it imports LeRobot once,
then rebuilds ``OUT/dataset`` from ``OUT/logs`` each time a line arrives on stdin, answering
one line on stdout (``ok``, ``damaged`` or ``error <message>``); it exits when stdin closes, so
it never outlives its session.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import select
import subprocess
import sys
from pathlib import Path
from typing import IO

log = logging.getLogger(__name__)


class DatasetUpdater:
    """Brings ``out/dataset`` up to date with ``out/logs`` in one helper process, one build at a
    time; a request made while a build is going starts another after it.

    Building in-process would import LeRobot (seconds of GIL) and stall the real-time loop. The
    helper is started by :meth:`warm` (when the first episode begins), so its imports overlap
    the flying instead of delaying the first build or the end of the session.
    """

    def __init__(self, out: Path) -> None:
        self.out = out
        self.proc: subprocess.Popen[str] | None = None
        self.busy = False
        self.pending = False
        self.failures = 0
        self.built = False

    def warm(self) -> None:
        """Start the helper (idempotent)."""
        if self.proc is None:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", __name__, str(self.out)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,  # LeRobot's import noise; errors come on stdout
                env={**os.environ, "HF_HUB_OFFLINE": "1"},
                text=True,
            )

    def request(self) -> None:
        if self.busy:
            self.pending = True
        else:
            self._send()

    def poll(self) -> None:
        """Take a finished build's answer, if there is one, without waiting."""
        if self.busy and self._readable():
            self._answer()
            if self.pending:
                self._send()

    def close(self) -> bool:
        """Finish outstanding work and stop the helper; True if a dataset was built."""
        while self.busy or self.pending:
            if not self.busy:
                self._send()
            self._answer()
        if self.proc is not None:
            assert self.proc.stdin is not None
            with contextlib.suppress(OSError):
                self.proc.stdin.close()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
            self.proc = None
        return self.built

    def _send(self) -> None:
        self.pending = False
        for _ in range(2):
            self.warm()
            assert self.proc is not None and self.proc.stdin is not None
            try:
                self.proc.stdin.write("build\n")
                self.proc.stdin.flush()
                self.busy = True
                return
            except OSError:  # the helper died: start another
                self.proc = None
        self._failed("the helper process does not start")

    def _readable(self) -> bool:
        assert self.proc is not None and self.proc.stdout is not None
        return bool(select.select([self.proc.stdout], [], [], 0)[0])

    def _answer(self) -> None:
        assert self.proc is not None and self.proc.stdout is not None
        line = self.proc.stdout.readline().strip()
        self.busy = False
        if line == "ok":
            self.built = True
        elif line == "damaged":
            self.built = True
            self._failed("some logged episodes could not be read")
        else:
            self._failed(json.loads(line[6:]) if line.startswith("error ") else "it exited")
        if not line:  # it exited: the next request starts another
            self.proc = None

    def _failed(self, why: str) -> None:
        self.failures += 1
        self.busy = self.pending = False
        log.error(
            "updating the dataset failed (the logs keep everything; run "
            "`python -m gymfg_il.collect recover %s`): %s",
            self.out,
            why[-2000:],
        )


def serve(out: Path, requests: IO[str], answers: IO[str]) -> None:
    """Rebuild ``out/dataset`` for every line on ``requests``; one answer line each."""
    from gymfg_il.collectors.commands import recover

    for _ in requests:
        try:
            with contextlib.redirect_stdout(sys.stderr):  # the report is not an answer
                code = recover(out)
            answers.write("ok\n" if code == 0 else "damaged\n")
        except Exception as err:  # the session reports it; the logs keep everything
            answers.write(f"error {json.dumps(f'{type(err).__name__}: {err}')}\n")
        answers.flush()


if __name__ == "__main__":
    from gymfg_il.datasets import lerobot_api

    lerobot_api.hub_offline()
    lerobot_api.load()  # the heavy imports, while the session flies
    serve(Path(sys.argv[1]), sys.stdin, sys.stdout)
