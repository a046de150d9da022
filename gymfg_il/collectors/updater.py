"""Keeping a session's dataset up to date without stalling the real-time loop."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

log = logging.getLogger(__name__)


class DatasetUpdater:
    """Brings ``out/dataset`` up to date with ``out/logs`` in a helper process (``collect
    recover``), one run at a time; a request made while a run is going starts another after.

    Building in-process would import LeRobot (seconds of GIL) and stall the real-time loop.
    """

    def __init__(self, out: Path) -> None:
        self.out = out
        self.proc: subprocess.Popen[bytes] | None = None
        self.pending = False
        self.failures = 0

    def _launch(self) -> None:
        cmd = [sys.executable, "-m", "gymfg_il.collect", "recover", str(self.out)]
        self.proc = subprocess.Popen(
            cmd,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            env={**os.environ, "HF_HUB_OFFLINE": "1"},
        )
        self.pending = False

    def request(self) -> None:
        if self.proc is None:
            self._launch()
        else:
            self.pending = True

    def poll(self) -> None:
        if self.proc is not None and self.proc.poll() is not None:
            self.failures += self.proc.returncode != 0
            self.proc = None
            if self.pending:
                self._launch()

    def close(self) -> bool:
        """Finish outstanding work; True if a dataset was built."""
        built = False
        while self.proc is not None or self.pending:
            if self.proc is None:
                self._launch()
            assert self.proc is not None
            _, err = self.proc.communicate()
            if self.proc.returncode != 0:
                self.failures += 1
                log.error(
                    "updating the dataset failed (the logs keep everything; run "
                    "`python -m gymfg_il.collect recover %s`): %s",
                    self.out,
                    err.decode(errors="replace")[-2000:],
                )
            else:
                built = True
            self.proc = None
        return built
