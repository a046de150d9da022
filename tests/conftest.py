"""Shared fixtures: small factories for envs, free UDP ports, an X server of a test's own, and
a tiny dataset of autopilot demonstrations."""

from __future__ import annotations

import contextlib
import os
import select
import shutil
import socket
import subprocess

import pytest

XVFB_DEADLINE_S = 180  # a loaded 2-core machine is slow; only a failure waits this long

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")


@pytest.fixture
def make_env():
    """Factory for single-aircraft envs that are closed after the test."""
    from gymfg_il.envs.single import AircraftEnv

    made = []

    def make(task="altitude", aircraft="c172p", **kwargs):
        env = AircraftEnv(task, aircraft, **kwargs)
        made.append(env)
        return env

    yield make
    for env in made:
        env.close()


def _free_udp_ports(n):
    """``n`` UDP ports free on loopback now, below 32768 (FlightGear keeps its multiplayer
    ports in a signed 16-bit property)."""
    found = []
    for port in range(23000 + os.getpid() % 8000, 32000):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                continue
        found.append(port)
        if len(found) == n:
            return found
    raise RuntimeError("no free UDP ports below 32000")


@pytest.fixture(scope="session")
def free_udp_ports():
    """``free_udp_ports(n)``: ``n`` UDP ports free now that FlightGear could use too."""
    return _free_udp_ports


@contextlib.contextmanager
def _xvfb(screen):
    """Xvfb on a display it picks itself (-displayfd), ready when this yields ``:N``: a display
    another test or person runs is never shared, and nothing waits a fixed time for it."""
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
        ready, _, _ = select.select([read], [], [], XVFB_DEADLINE_S)  # written once it accepts
        number = os.read(read, 64).decode().strip() if ready else ""
        assert number.isdigit(), "Xvfb never said which display it serves"
        yield f":{number}"
    finally:
        os.close(read)
        server.terminate()
        server.wait(30)


@pytest.fixture(scope="session")
def xvfb():
    """``with xvfb("1024x768x24") as display:`` an X server of the test's own (skipped with
    the reason when Xvfb is not installed)."""
    return _xvfb


@pytest.fixture(scope="session")
def tiny_dataset(tmp_path_factory):
    """Six 30-s altitude demonstrations (1,800 frames) with a little DART noise."""
    from gymfg_il.collectors.autopilot import record_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets.from_logs import build_from_logs

    out = tmp_path_factory.mktemp("tiny")
    cfg = CollectConfig(
        task="altitude", episodes=6, episode_time_s=30, noise=0.02, seed=1000, out=out
    )
    result = record_autopilot(cfg)
    build_from_logs([result.log], out / "dataset")
    return out / "dataset"
