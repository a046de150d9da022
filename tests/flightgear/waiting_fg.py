"""Waiting in the FlightGear tests: on conditions, with deadlines that only bound a failure,
never a fixed sleep (a busy 2-core machine draws FlightGear at 3-5 frames a second, and
stalls it for seconds). The X server it draws in is the ``xvfb`` fixture (tests/conftest.py)."""

import time

import pytest

from gymfg_il.flightgear.launcher import find_fgfs

DEADLINE_S = 180  # a loaded 2-core machine is slow; only a failure waits this long


def needs_flightgear():
    """Skip the test, saying why, where FlightGear is not installed."""
    if find_fgfs() is None:
        pytest.skip("FlightGear is not installed (Debian: apt-get install flightgear)")


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
