"""Input-to-record latency: from a real key event in a real window (xdotool's X events, on the
X display ``DISPLAY`` names) to the action of the frame the manual session records.

Run as ``python -m benchmarks.latency PRESSES`` on a display of its own (Xvfb); it prints one
JSON line: each press's latency in ms and in agent steps, the presses never recorded (a
press the session never saw) and the frames that came late. A session at 30 Hz flies the
altitude task in real time; a thread holds Left, then Right, for 0.3 s about once a second
(at a random phase of the frame), starting each press with ``xdotool keydown``. A press counts
from the moment before xdotool is started (so its start-up is counted against us) to the
start of the frame whose recorded action first moves the stick that way; its steps are the
frames that started between the two (0: the next frame recorded it; the loop reads input
once a frame).
"""

from __future__ import annotations

import itertools
import json
import os
import random
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

SIDES = ("Left", "Right")  # pressed in turn, so the aircraft's bank stays near level


def _xdo(*args: str) -> str:
    done = subprocess.run(["xdotool", *args], capture_output=True, text=True, timeout=30)
    return done.stdout


def measure(presses: int, seed: int = 0) -> dict[str, Any]:
    """Fly ``presses`` presses of Left; each one's latency (module docstring)."""
    os.environ.pop("SDL_VIDEODRIVER", None)  # the real window
    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    starts: list[float] = []  # perf_counter (CLOCK_MONOTONIC, as time.monotonic) per frame
    recorded: list[float] = []  # the aileron recorded by the frame before each
    sent: list[float] = []

    def on_frame(frame: int, session: ManualSession) -> None:
        starts.append(time.perf_counter())
        flying = session.stages.phases.state == "recording"
        recorded.append(float(session.stages.log.last_action[0]) if flying else float("nan"))

    def press() -> None:
        rng = random.Random(seed)
        found = ""
        while not found:
            found = (_xdo("search", "--onlyvisible", "--classname", ".").split() or [""])[0]
            time.sleep(0.1)
        _xdo("mousemove", "450", "300")  # no window manager: focus follows the pointer
        _xdo("key", "space")  # start the episode
        time.sleep(1.0)
        for i in range(presses):
            key = SIDES[i % 2]
            time.sleep(rng.uniform(0.0, 1 / 30))  # any phase of the frame
            sent.append(time.perf_counter())
            _xdo("keydown", key)
            time.sleep(0.3)
            _xdo("keyup", key)
            time.sleep(0.7)  # the stick centres again (1/s) before the next press
        _xdo("key", "q")  # quit (the episode in flight is discarded)

    with tempfile.TemporaryDirectory() as tmp:
        cfg = ManualConfig(
            task="altitude", episode_time_s=presses + 30, agent_hz=30, episodes=0, out=Path(tmp)
        )
        session = ManualSession(cfg, on_frame, realtime=True)
        thread = threading.Thread(target=press, daemon=True)
        thread.start()
        session.run()
    return _latencies(starts, recorded, sent, 1 / 30)


def _latencies(
    starts: list[float], recorded: list[float], sent: list[float], period: float
) -> dict[str, Any]:
    ms, steps, missed = [], [], []
    for i, t in enumerate(sent):
        after = next(k for k, s in enumerate(starts) if s > t)  # the first frame to read it
        end = (
            len(starts) - 1
            if i + 1 == len(sent)
            else next(k for k, s in enumerate(starts) if s > sent[i + 1])
        )
        # frame k's record is seen at frame k + 1's start; it moved that way: it read the press
        way = -1.0 if i % 2 == 0 else 1.0
        moved = [k for k in range(after, end) if way * (recorded[k + 1] - recorded[k]) > 1e-9]
        if not moved:  # never recorded before the next press
            missed.append(i)
            continue
        ms.append(1000.0 * (starts[moved[0]] - t))
        steps.append(moved[0] - after)
    periods = [b - a for a, b in itertools.pairwise(starts)]
    late = sum(p > 1.5 * period for p in periods)
    return {
        "ms": ms,
        "steps": steps,
        "missed": missed,
        "late_frames": late,
        "period_ms": 1000.0 * period,
    }


def on_display(display: str, presses: int) -> dict[str, Any]:
    """``python -m benchmarks.latency PRESSES`` on X display ``display``, its JSON read."""
    env = {**os.environ, "DISPLAY": display, "HF_HUB_OFFLINE": "1"}
    env.pop("SDL_VIDEODRIVER", None)
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.latency", str(presses)],
        env=env,
        cwd=Path(__file__).resolve().parents[1],
        capture_output=True,
        text=True,
        timeout=120 + 5 * presses,
    )
    if done.returncode:
        raise RuntimeError(f"benchmarks.latency failed: {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def on_own_display(presses: int) -> dict[str, Any]:
    """``on_display`` on an Xvfb of its own (it picks a free display: -displayfd)."""
    import select

    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
        pass_fds=(write,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    try:
        ready, _, _ = select.select([read], [], [], 60)
        number = os.read(read, 64).decode().strip() if ready else ""
        if not number.isdigit():
            raise RuntimeError("Xvfb never said which display it serves")
        return on_display(f":{number}", presses)
    finally:
        os.close(read)
        server.terminate()
        server.wait(30)


if __name__ == "__main__":
    print(json.dumps(measure(int(sys.argv[1]) if len(sys.argv) > 1 else 20)))
