"""The web cockpit: eight headless web pilots (``gymfg_il.web.headless``) fly a real
``collect web`` server at once over loopback, at 30 Hz, on the approach (the busiest display).

Rows: ``web_8_pilots_p99_period_error_ms`` (each pilot's p99 |frame period - 1/30 s|, from the
wall clock each recorded step's input was read at; the worst pilot's) and
``web_input_to_record_p99_steps`` (the frames between the frame a page answered and the step
that flew its answer, p99 per episode, the worst pilot's; 1 is the next step). The detail says
the late frames, the input's round trip and the server's CPU per pilot.

    python -m benchmarks.web [--quick]
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.common import Row, print_rows


def _cpu_s(pid: int) -> float:
    """CPU seconds (user + system, every thread) the process has used."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _serve(out: Path, pilots: int, seconds: float) -> tuple[subprocess.Popen, str, list[str]]:
    """A ``collect web`` server in a process of its own: it, its websocket, the invites."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.collect", "web", "--out", str(out), "--port", "0",
         "--pilots", str(pilots), "--episode-time", f"{seconds:g}", "--task", "approach"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy",
             "PYTHONUNBUFFERED": "1"},
    )  # fmt: skip
    assert proc.stdout is not None
    base, tokens = "", []
    for line in proc.stdout:
        found = re.search(r"serving the web cockpit at (http://\S+?)/ ", line)
        if found:
            base = found.group(1)
        token = re.search(r"#invite=(\S+)$", line)
        if token:
            tokens.append(token.group(1))
        if "waiting for pilots" in line:
            return proc, base.replace("http://", "ws://") + "/ws", tokens
    raise RuntimeError(f"the server did not start (exit {proc.wait()})")


def web_pilots(pilots: int, seconds: float) -> list[Row]:
    from gymfg_il.recording.reader import read_log
    from gymfg_il.web.headless import fly_many

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "web"
        proc, ws, tokens = _serve(out, pilots, seconds)
        try:
            cpu, started = _cpu_s(proc.pid), time.perf_counter()
            flown = asyncio.run(fly_many(ws, tokens, 1))
            cpu, wall = _cpu_s(proc.pid) - cpu, time.perf_counter() - started
        finally:
            proc.send_signal(signal.SIGINT)
            said_by_server = proc.communicate(timeout=120)[0]
        episodes = [
            e
            for log in sorted((out / "logs").glob("*.mcap"))
            for e in read_log(log).complete_episodes
        ]
    saved = sum(f.saved for f in flown)
    if saved < pilots:  # say why, from both ends
        closed = "; ".join(repr(f.closed) for f in flown if not f.saved)
        print(f"only {saved} of {pilots} saved; closed: {closed}\n{said_by_server[-3000:]}")
    period_p99, ages, delays, late = [], [], [], 0
    for episode in episodes:
        clock = episode.steps["ego"].wall_time
        periods = np.diff(clock)[1:]  # the first follows the reset's frame
        period_p99.append(float(np.percentile(np.abs(periods - 1 / 30) * 1000, 99)))
        ages.append(int(episode.end.get("input_age_frames", -1)))
        delays.append(float(episode.end.get("input_delay_ms", -1.0)))
        late += int(episode.end.get("late_frames", 0))
    share = 100 * cpu / wall / pilots
    said = (
        f"{pilots} headless web pilots at 30 Hz over loopback, {seconds:g} s of the approach "
        f"each ({saved} episodes saved): {late} late frames; server CPU {share:.1f} % of a core "
        "a pilot"
    )
    return [
        Row(
            f"web_{pilots}_pilots_p99_period_error_ms",
            max(period_p99) if period_p99 else float("nan"),
            "ms",
            5.0,
            higher_is_better=False,
            detail=[
                said,
                "each pilot's p99 period error (ms): " + ", ".join(f"{v:.2f}" for v in period_p99),
            ],
        ),
        Row(
            "web_input_to_record_p99_steps",
            float(max(ages)) if ages else float("nan"),
            "steps",
            1.0,
            higher_is_better=False,
            at_most=True,
            detail=[
                "frames from the frame a page answered to the step that flew the answer (1: "
                "the next), p99 per pilot: "
                + ", ".join(str(a) for a in ages)
                + "; the input's round trip p99 (ms): "
                + ", ".join(f"{d:.1f}" for d in delays)
            ],
        ),
    ]


def rows(quick: bool) -> list[Row]:
    return web_pilots(8, 10 if quick else 30)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--quick", action="store_true", help="10 s episodes instead of 30")
    p.add_argument("--pilots", type=int, default=8, help="headless web pilots at once")
    args = p.parse_args(argv)
    print_rows(web_pilots(args.pilots, 10 if args.quick else 30))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
