"""A real web cockpit server in a process of its own (``collect web --port 0``), read from
its output: the address, each pilot's invite, and what it says as pilots come and go."""

from __future__ import annotations

import contextlib
import os
import queue
import re
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

pytest.importorskip("starlette", reason="the web cockpit's extra: pip install -e '.[web]'")
pytest.importorskip("uvicorn", reason="the web cockpit's extra: pip install -e '.[web]'")
pytest.importorskip("websockets", reason="the web cockpit's extra: pip install -e '.[web]'")

START_S = 120  # a busy 2-core machine imports and builds slowly; only a failure waits this long


@dataclass
class Served:
    proc: subprocess.Popen
    out: Path
    base: str = ""
    invites: dict[str, str] = field(default_factory=dict)
    lines: list[str] = field(default_factory=list)
    _queue: queue.Queue = field(default_factory=queue.Queue)

    @property
    def ws(self) -> str:
        return self.base.replace("http://", "ws://") + "/ws"

    def _pump(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))
            self._queue.put(line)

    def wait_for(self, pattern: str, timeout: float = START_S) -> str:
        """The first line of output (from any time) matching ``pattern``."""
        deadline = time.monotonic() + timeout
        seen = 0
        while time.monotonic() < deadline:
            for line in self.lines[seen:]:
                if re.search(pattern, line):
                    return line
            seen = len(self.lines)
            if self.proc.poll() is not None and self._queue.empty():
                break
            with contextlib.suppress(queue.Empty):
                self._queue.get(timeout=0.2)
        raise AssertionError(f"no line matching {pattern!r}; output:\n" + "\n".join(self.lines))

    def said(self, pattern: str) -> list[str]:
        return [line for line in self.lines if re.search(pattern, line)]

    def stop(self, timeout: float = 120) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(2)  # Ctrl-C: the server finishes the dataset
        try:
            return self.proc.wait(timeout)
        finally:
            if self.proc.poll() is None:
                self.proc.kill()


@pytest.fixture
def serve(tmp_path):
    """``serve(*args, out=None)``: a running ``collect web`` (``Served``), stopped after."""
    made: list[Served] = []

    def start(*args: str, out: Path | None = None) -> Served:
        out = out or tmp_path / f"web{len(made)}"
        env = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}
        env["PYTHONUNBUFFERED"] = "1"
        proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "gymfg_il.collect",
                "web",
                "--out",
                str(out),
                "--port",
                "0",
                *list(args),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
        )
        served = Served(proc, out)
        made.append(served)
        threading.Thread(target=served._pump, daemon=True).start()
        line = served.wait_for(r"serving the web cockpit at ")
        served.base = re.search(r"(http://\S+?)/ ", line).group(1)
        served.wait_for(r"invite\(s\); waiting for pilots")
        for line in served.said(r"^invite "):
            name, token = re.match(r"invite (.+): \S+#invite=(\S+)$", line).groups()
            served.invites[name] = token
        return served

    yield start
    for served in made:
        if served.proc.poll() is None:
            served.stop()
