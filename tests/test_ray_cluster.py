"""Collection and evaluation on a real two-node Ray cluster on this machine (a head and a
second node, started with `ray start`): identical to one process, also when a worker running
an episode is killed."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gymfg_il import collect
from gymfg_il import eval as evaluate

# Ray 2.60 starts a head with token authentication; whoever joins or connects (the second
# node, the collect and eval drivers) must say so before Ray is imported, and reads the
# head's token from ~/.ray/auth_token
os.environ.setdefault("RAY_AUTH_MODE", "token")
pytest.importorskip("ray")
pytestmark = pytest.mark.ray
RAY = str(Path(sys.executable).parent / "ray")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    port = _free_port()
    address = f"127.0.0.1:{port}"
    env = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0", "RAY_worker_niceness": "0"}
    common = ["--num-cpus=1", "--disable-usage-stats"]
    head = [RAY, "start", "--head", f"--port={port}", "--include-dashboard=false", *common]
    subprocess.run(head, env=env, check=True, capture_output=True, timeout=120)
    try:
        second = [RAY, "start", f"--address={address}", *common]
        subprocess.run(second, env=env, check=True, capture_output=True, timeout=120)
        import ray

        ray.init(address=address, log_to_driver=False)
        deadline = time.monotonic() + 60
        while len([n for n in ray.nodes() if n["Alive"]]) < 2:
            assert time.monotonic() < deadline, "the second node never joined"
            time.sleep(0.5)
        ray.shutdown()
        yield address
    finally:
        subprocess.run([RAY, "stop", "--force"], env=env, capture_output=True, timeout=120)


def _collect(out: Path, *extra: str) -> None:
    argv = ["autopilot", "--task", "roll", "--episodes", "4", "--episode-time", "10"]
    assert collect.main([*argv, "--out", str(out), "--no-progress", *extra]) == 0


def _frames(out: Path) -> bytes:
    return (out / "dataset/data/chunk-000/file-000.parquet").read_bytes()


def test_collection_on_the_cluster_is_identical_to_one_process(cluster, tmp_path):
    _collect(tmp_path / "ray", "--ray", cluster)
    _collect(tmp_path / "one")
    assert _frames(tmp_path / "ray") == _frames(tmp_path / "one")


def test_eval_rows_on_the_cluster_match_one_process(cluster, tmp_path):
    argv = ["--task", "roll", "--episodes", "3", "--episode-time", "10", "--no-progress"]
    assert evaluate.main([*argv, "--ray", cluster, "--json", str(tmp_path / "r.json")]) == 0
    assert evaluate.main([*argv, "--json", str(tmp_path / "o.json")]) == 0
    assert json.loads((tmp_path / "r.json").read_text()) == json.loads(
        (tmp_path / "o.json").read_text()
    )


def test_a_killed_worker_loses_nothing(cluster, tmp_path):
    out = tmp_path / "killed"
    argv = ["autopilot", "--task", "roll", "--episodes", "6", "--episode-time", "40"]
    run = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gymfg_il.collect",
            *argv,
            "--out",
            str(out),
            "--no-progress",
            "--ray",
            cluster,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    killed = None
    deadline = time.monotonic() + 120
    while killed is None and run.poll() is None and time.monotonic() < deadline:
        found = subprocess.run(["pgrep", "-f", "ray::_seed_task"], capture_output=True, text=True)
        pids = [int(p) for p in found.stdout.split()]
        if pids:
            killed = pids[0]
            os.kill(killed, signal.SIGKILL)
        time.sleep(0.05)
    _stdout, stderr = run.communicate(timeout=600)
    assert killed is not None, "no worker was seen running an episode"
    assert run.returncode == 0, stderr[-2000:]
    _collect_once = tmp_path / "one"
    argv_one = ["autopilot", "--task", "roll", "--episodes", "6", "--episode-time", "40"]
    assert collect.main([*argv_one, "--out", str(_collect_once), "--no-progress"]) == 0
    assert _frames(out) == _frames(_collect_once)
