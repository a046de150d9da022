"""Waiting in the FlightGear tests: on conditions, with deadlines that only bound a failure,
never a fixed sleep (a busy 2-core machine draws FlightGear at 3-5 frames a second, and
stalls it for seconds); and an X server of the tests' own."""

import contextlib
import os
import select
import shutil
import subprocess
import time

import pytest

from gymfg_il.viz.flightgear import find_fgfs

DEADLINE_S = 180  # a loaded 2-core machine is slow; only a failure waits this long


@contextlib.contextmanager
def xvfb(screen):
    """Xvfb on a display it picks itself (-displayfd), ready when this yields ``:N``: a display
    another test or person runs is never shared, and nothing waits a fixed time for it."""
    if find_fgfs() is None:
        pytest.skip("FlightGear is not installed (Debian: apt-get install flightgear)")
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (Debian: apt-get install xvfb)")
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", screen, "-nolisten", "tcp"],
        pass_fds=(write,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    try:
        ready, _, _ = select.select([read], [], [], DEADLINE_S)  # written once it accepts
        number = os.read(read, 64).decode().strip() if ready else ""
        assert number.isdigit(), "Xvfb never said which display it serves"
        yield f":{number}"
    finally:
        os.close(read)
        server.terminate()
        server.wait(30)


def wait_until(condition, what, deadline_s=DEADLINE_S):
    """``condition()``'s first true value; AssertionError naming ``what`` after the deadline."""
    deadline = time.monotonic() + deadline_s
    while True:
        value = condition()
        if value:
            return value
        assert time.monotonic() < deadline, f"not within {deadline_s:g} s: {what}"
        time.sleep(0.01)


def wait_flightgear_time(fg, seconds, frames=3, deadline_s=DEADLINE_S):
    """Let ``fg`` run ``seconds`` of its own clock and at least ``frames`` frames, however
    slowly it draws them (its property server answers once a frame; its clock advances
    only in frames)."""
    start = last = fg.get_float("/sim/time/elapsed-sec")
    seen = 0
    deadline = time.monotonic() + deadline_s
    while last - start < seconds or seen < frames:
        assert time.monotonic() < deadline, f"FlightGear ran {last - start:.2f} s, {seen} frames"
        now = fg.get_float("/sim/time/elapsed-sec")
        if now > last:
            seen, last = seen + 1, now
