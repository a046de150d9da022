"""A real window under Xvfb, real key presses from xdotool: the person's keys reach the data."""

import os
import shutil
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.display

NEEDED = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]


@pytest.fixture
def display():
    if NEEDED:
        pytest.skip(f"needs {', '.join(NEEDED)} (Debian: apt-get install xvfb xdotool)")
    number = 90 + os.getpid() % 9
    server = subprocess.Popen(
        ["Xvfb", f":{number}", "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1.0)
    try:
        yield f":{number}"
    finally:
        server.terminate()
        server.wait(5)


def xdo(display, *args):
    return subprocess.run(
        ["xdotool", *args],
        env={**os.environ, "DISPLAY": display},
        capture_output=True,
        text=True,
        timeout=10,
    )


def test_keys_typed_into_a_real_window_become_the_dataset(display, tmp_path):
    env = {**os.environ, "DISPLAY": display, "HF_HUB_OFFLINE": "1"}
    env.pop("SDL_VIDEODRIVER", None)
    out = tmp_path / "session"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gymfg_il.collect",
            "manual",
            "--episodes",
            "1",
            "--episode-time",
            "4",
            "--out",
            str(out),
        ],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        # Xvfb runs no window manager: wait for the window to be mapped, then put the pointer
        # over it (focus follows the pointer) and type as a person would.
        window = ""
        deadline = time.time() + 40
        while not window and time.time() < deadline:
            found = xdo(display, "search", "--onlyvisible", "--name", ".*").stdout.split()
            window = found[0] if found else ""
            time.sleep(0.3)
        assert window, "the GUI window never appeared"
        time.sleep(1.0)
        xdo(display, "mousemove", "450", "300")
        xdo(display, "key", "space")
        time.sleep(0.5)
        xdo(display, "keydown", "Left")
        time.sleep(0.6)
        xdo(display, "keyup", "Left")
        output = proc.communicate(timeout=120)[0].decode()  # a loaded 2-core machine is slow
    finally:
        proc.kill()
    assert proc.returncode == 0, output
    assert "saved 1 episode" in output
    from gymfg_il.learning.data import load_frames

    frames = load_frames(out / "dataset")
    assert len(frames) == 120  # 4 s at 30 Hz
    assert frames.action[:, 0].min() < -0.3  # the Left key rolled the stick left
