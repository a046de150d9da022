"""Keeping a session's dataset up to date without stalling the real-time loop.

``python -m gymfg_il.cockpit.updater OUT`` is the helper process: it imports LeRobot once,
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
import tempfile
from pathlib import Path
from typing import IO

log = logging.getLogger(__name__)


class DatasetUpdater:
    """Brings ``out/dataset`` up to date with ``out/logs`` in one helper process, one build at a
    time; a request made while a build is going starts another after it.

    Building in-process would import LeRobot (seconds of GIL) and stall the real-time loop. The
    helper is started by :meth:`warm` (when the first episode begins), so its imports overlap
    the flying instead of delaying the first build or the end of the session. It runs in a
    session of its own, so a Ctrl-C meant for the collector does not cut a build short.
    """

    def __init__(self, out: Path) -> None:
        self.out = out
        self.proc: subprocess.Popen[str] | None = None
        self.errors: IO[bytes] | None = None  # the helper's stderr, for a failure's report
        self.busy = False
        self.pending = False
        self.sent = False
        self.failures = 0
        self.built = False

    def warm(self) -> None:
        """Start the helper (idempotent)."""
        if self.proc is not None:
            return
        if self.errors is None:  # kept until close(): a failure's report reads its tail
            self.errors = tempfile.TemporaryFile()  # noqa: SIM115
        try:
            self.proc = subprocess.Popen(
                [sys.executable, "-m", __name__, str(self.out)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=self.errors,
                env={**os.environ, "HF_HUB_OFFLINE": "1"},
                text=True,
                start_new_session=True,
            )
        except OSError as err:
            self._failed(f"the helper process does not start: {err}")

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
            if self.busy:
                self._answer()
        if self.proc is not None and not self.sent:
            self.proc.kill()  # never asked for a build: do not wait for its imports
        self._discard()
        if self.errors is not None:
            self.errors.close()
            self.errors = None
        return self.built

    def _send(self) -> None:
        self.pending = False
        for _ in range(2):
            self.warm()
            if self.proc is None or self.proc.stdin is None:
                return
            try:
                self.proc.stdin.write("build\n")
                self.proc.stdin.flush()
                self.busy = self.sent = True
                return
            except OSError:  # the helper died: start another
                self._discard()
        self._failed("the helper process exits as soon as it starts")

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
        elif line.startswith("error "):
            self._failed(json.loads(line[6:]))
        else:  # it exited: the next request starts another
            self._discard()
            self._failed("the helper process exited")

    def _discard(self) -> None:
        """Stop and reap the helper, closing its pipes."""
        if self.proc is not None:
            for pipe in (self.proc.stdin, self.proc.stdout):
                with contextlib.suppress(OSError):
                    if pipe is not None:
                        pipe.close()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
            self.proc = None

    def _failed(self, why: str) -> None:
        self.failures += 1
        tail = ""
        if self.errors is not None:
            self.errors.seek(0)
            tail = self.errors.read().decode(errors="replace")[-2000:]
        log.error(
            "updating the dataset failed (the logs keep everything; run "
            "`python -m gymfg_il.collect recover %s`): %s%s",
            self.out,
            why,
            f"\n{tail}" if tail and "exit" in why else "",
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
    # the real-time loops it serves (a person's frames, a web server's pilots) come first:
    # on a machine of few cores a build runs beside them at a lower priority
    with contextlib.suppress(OSError):
        os.nice(10)
    answers = os.fdopen(os.dup(1), "w")  # answers get a descriptor of their own;
    os.dup2(2, 1)  # whatever else writes to stdout (a library, C code) goes to stderr
    from gymfg_il.datasets import lerobot_api

    lerobot_api.hub_offline()
    lerobot_api.load()  # the heavy imports, while the session flies
    serve(Path(sys.argv[1]), sys.stdin, answers)
    # every build is answered and on disk: leave without the interpreter's teardown of torch
    # and LeRobot (about a second the session would wait for at its end)
    answers.close()
    sys.stderr.flush()
    os._exit(0)
