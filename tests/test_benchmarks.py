"""The benchmarks print their rows, not the online clients' waits for one another."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.network
def test_the_online_benchmark_keeps_the_clients_waits_to_itself():
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.online", "--rate", "4", "20"],
        cwd=ROOT,
        env={**os.environ, "HF_HUB_OFFLINE": "1"},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.strip()) > 0  # steps/s, and nothing else
    assert "waiting for" not in done.stderr, done.stderr
