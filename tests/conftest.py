"""Shared fixtures: small factories for envs, free UDP ports, an X server of a test's own, a
tiny dataset of autopilot demonstrations, and a small recurrent policy with the check that
whoever flies it carries its state (``tiny_gru``, ``carried_state``)."""

from __future__ import annotations

import atexit
import contextlib
import os
import select
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

SAMPLE = Path(__file__).resolve().parents[1] / "datasets/sample-altitude-c172p/dataset"
XVFB_DEADLINE_S = 180  # a loaded 2-core machine is slow; only a failure waits this long

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
# Hugging Face datasets caches every parquet file LeRobot opens as Arrow under
# ~/.cache/huggingface/datasets and never removes it: a test run opens thousands (GBs over a
# few runs). The tests' own cache goes with the run (set before anything imports datasets).
_HF_CACHE = tempfile.mkdtemp(prefix="gymfg-hf-datasets-")
os.environ["HF_DATASETS_CACHE"] = _HF_CACHE
atexit.register(shutil.rmtree, _HF_CACHE, ignore_errors=True)


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


@pytest.fixture(scope="session")
def tiny_gru(tmp_path_factory):
    """The checkpoint folder of a small recurrent (GRU) policy trained for a few seconds on
    the bundled sample: it flies altitude on the c172p at 10 Hz, with a memory."""
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.policies.configuration_gru import GRUConfig

    out = tmp_path_factory.mktemp("gru")
    gru = GRUConfig(hidden=16, sequence_length=4)
    train_bc(TrainConfig(dataset=SAMPLE, out=out, policy=gru, epochs=3, seed=0))
    return out


# Stepwise and whole-episode GRU actions differ in float32 rounding: MKL's sgemm sums a
# single row (one step) in another order than a block of rows (the whole episode), in the
# encoder, the GRU's input projection and the head (the recurrent projection is one row in
# both). Measured: at most 6.0e-8 over the sample's 20 episodes of 900 steps (hidden 16 and
# 256); 1e-6 is 8 float32 ulps at 1.0, and a state not carried (or not reset) moves the
# actions by 1e-2 and more.
STEP_VS_WINDOW_ATOL = 1e-6


def _whole_episode(policy, observations, carry=True):
    """A recurrent policy's actions for one episode's observations (steps, n_obs), clipped
    as the rollout clips them: its module run over the whole sequence at once
    (``policy.forward(obs[None])``), or, without ``carry``, every step from a fresh state."""
    import torch

    from gymfg_il.envs.actions import clip

    obs = torch.as_tensor(np.asarray(observations, dtype=np.float32))
    with torch.no_grad():
        pred, _ = policy.forward(obs[None] if carry else obs[:, None])
        raw = policy.action_norm.inverse(pred[0] if carry else pred[:, 0])
    return np.array([clip(a) for a in raw.double().numpy()])


@pytest.fixture(scope="session")
def carried_state():
    """``carried_state(policy, observations, actions, flown=None)`` asserts that ``actions``
    (clipped), flown over one whole episode, are what the recurrent ``policy`` gives with its
    state fresh at the episode's first step and carried through every step (the GRU over the
    whole sequence at once), and that this could fail: without the state carried they
    differ. ``flown``: the steps whose action was the policy's (a person flew the others;
    their observations still count). Returns the largest difference."""

    def check(policy, observations, actions, flown=None):
        assert len(observations) == len(actions) > 1
        mask = np.ones(len(actions), bool) if flown is None else np.asarray(flown, bool)
        whole = _whole_episode(policy, observations)[mask]
        gap = float(np.abs(np.asarray(actions)[mask] - whole).max())
        assert gap <= STEP_VS_WINDOW_ATOL, f"the flown actions are {gap:.3g} off"
        stateless = _whole_episode(policy, observations, carry=False)[mask]
        assert np.abs(stateless - whole).max() > 1e3 * STEP_VS_WINDOW_ATOL
        return gap

    return check
