"""A real window under Xvfb, real key presses from xdotool: the person's keys reach the data."""

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.display

NEEDED = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]
DEADLINE_S = 180  # a loaded 2-core machine is slow; only a failure waits this long


@pytest.fixture
def display(xvfb):
    """An X server of our own (tests/conftest.py), with xdotool to type into it."""
    if NEEDED:
        pytest.skip(f"needs {', '.join(NEEDED)} (Debian: apt-get install xvfb xdotool)")
    with xvfb("1024x768x24") as display:
        yield display


def xdo(display, *args):
    return subprocess.run(
        ["xdotool", *args],
        env={**os.environ, "DISPLAY": display},
        capture_output=True,
        text=True,
        timeout=30,
    )


def test_keys_typed_into_a_real_window_become_the_dataset(display, tmp_path):
    env = {**os.environ, "DISPLAY": display, "HF_HUB_OFFLINE": "1"}
    env.pop("SDL_VIDEODRIVER", None)
    out = tmp_path / "session"
    argv = ["manual", "--episodes", "1", "--episode-time", "4", "--out", str(out)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.collect", *argv],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        # Xvfb runs no window manager: wait for the session's window to be mapped, then put
        # the pointer over it (focus follows the pointer) and fly as a person would: Space
        # starts the episode, Left held rolls left. Neither is timed: both are pressed again
        # until the session, its one episode saved, exits (Space is ignored while flying;
        # the start of an episode releases held keys, and the next press holds Left again).
        deadline = time.monotonic() + DEADLINE_S
        window = ""
        while not window and proc.poll() is None and time.monotonic() < deadline:
            # the display is ours alone, so any mapped window with a class is the session's
            # (xdotool finds no window by its name here, with no window manager)
            found = xdo(display, "search", "--onlyvisible", "--classname", ".").stdout.split()
            window = found[0] if found else ""
            time.sleep(0.2)
        assert window, "the GUI window never appeared"
        xdo(display, "mousemove", "450", "300")
        while proc.poll() is None and time.monotonic() < deadline:
            xdo(display, "key", "space")
            # release first: a second keydown of a key X holds down is a key repeat, which
            # pygame drops, so a Left pressed before the start cleared it was never seen again
            xdo(display, "keyup", "Left")
            xdo(display, "keydown", "Left")
            time.sleep(0.2)
        xdo(display, "keyup", "Left")
        output = proc.communicate(timeout=30)[0].decode()
    finally:
        proc.kill()
    assert proc.returncode == 0, output
    assert "saved 1 episode" in output
    from gymfg_il.learning.data import load_frames

    frames = load_frames(out / "dataset")
    assert len(frames) == 120  # 4 s at 30 Hz
    assert frames.action[:, 0].min() < -0.3  # the Left key rolled the stick left


def test_a_real_key_press_reaches_the_record_within_a_frame(display):
    """Real X key events (xdotool) into a real window: every press is recorded, by the first
    frame that could read it or the next (``benchmarks.latency``; the benchmark row
    input_to_record_p99_steps measures more presses)."""
    import json

    import numpy as np

    env = {**os.environ, "DISPLAY": display, "HF_HUB_OFFLINE": "1"}
    env.pop("SDL_VIDEODRIVER", None)
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.latency", "12"],
        cwd=Path(__file__).resolve().parents[2],
        env=env,
        capture_output=True,
        text=True,
        timeout=DEADLINE_S,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["missed"] == []  # no press lost
    ms, steps = np.array(found["ms"]), np.array(found["steps"])
    assert len(ms) == 12 and np.median(steps) <= 1  # xdotool's start-up counts against us
    assert ms.max() < 4 * found["period_ms"], ms  # a busy machine delays frames, not input
