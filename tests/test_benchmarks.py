"""The benchmarks print their rows, not the online clients' waits for one another."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _benchmark(name: str, *args: str) -> subprocess.CompletedProcess[str]:
    """``python -m benchmarks.NAME ARGS`` from the repository's root, its output captured."""
    return subprocess.run(
        [sys.executable, "-m", f"benchmarks.{name}", *args],
        cwd=ROOT,
        env={**os.environ, "HF_HUB_OFFLINE": "1"},
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.mark.network
def test_the_online_benchmark_keeps_the_clients_waits_to_itself():
    done = _benchmark("online", "--rate", "4", "20")
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.strip()) > 0  # steps/s, and nothing else
    assert "waiting for" not in done.stderr, done.stderr


@pytest.mark.slow
def test_the_rl_benchmark_prints_the_sampling_beside_its_ceiling():
    done = _benchmark("rl", "--quick", "--envs", "2")
    assert done.returncode == 0, done.stderr[-2000:]
    ratios = {
        line.split()[0]: float(line.split()[1])
        for line in done.stdout.splitlines()
        if line.startswith("rl_")
    }
    sampling = ratios["rl_sampling_vs_physics_bound"]
    alone = ratios["rl_envs_alone_vs_physics_bound"]
    # the same envs with no policy to run are the ceiling of any sampler
    assert 0 < sampling < alone, done.stdout
    # and the sampling over that ceiling has its own row, named for its env count (2 is not
    # train ppo's default of four a core; here cores = 2)
    assert 0 < ratios["rl_sampling_vs_envs_alone_2_envs"] < 1, done.stdout
    assert "ppo_1m_steps_wall_min" not in done.stdout  # only where no env count is asked for
