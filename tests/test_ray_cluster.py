"""Collection and evaluation on a real two-node Ray cluster on this machine (a head and a
second node, started with `ray start`): identical to one process, also when a worker running
an episode is killed, and when a whole node dies mid-run."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from gymfg_il import collect
from gymfg_il import eval as evaluate

# A machine that keeps a Ray token (~/.ray/auth_token) starts its clusters with token
# authentication; whoever joins or connects (the other nodes, the collect and eval drivers)
# must then say so before Ray is imported. The same rule as gymfg_il.workers.
if (Path.home() / ".ray" / "auth_token").is_file():
    os.environ.setdefault("RAY_AUTH_MODE", "token")
pytest.importorskip("ray")
pytestmark = pytest.mark.ray
RAY = str(Path(sys.executable).parent / "ray")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


ENV = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0", "RAY_worker_niceness": "0"}
NODE = ["--num-cpus=1", "--disable-usage-stats"]


def _ray(argv: list[str]) -> None:
    done = subprocess.run(argv, env=ENV, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"{' '.join(argv[1:3])} failed:\n{done.stderr[-3000:]}"


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    port = _free_port()
    address = f"127.0.0.1:{port}"
    head = [RAY, "start", "--head", f"--port={port}", "--include-dashboard=false", *NODE]
    _ray(head)
    try:
        _ray([RAY, "start", f"--address={address}", *NODE])
        import ray

        ray.init(address=address, log_to_driver=False)
        deadline = time.monotonic() + 60
        while len([n for n in ray.nodes() if n["Alive"]]) < 2:
            assert time.monotonic() < deadline, "the second node never joined"
            time.sleep(0.5)
        ray.shutdown()
        yield address
    finally:
        subprocess.run([RAY, "stop", "--force"], env=ENV, capture_output=True, timeout=120)


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


def _pids(pattern: str) -> list[int]:
    found = subprocess.run(["pgrep", "-f", pattern], capture_output=True, text=True)
    return [int(p) for p in found.stdout.split()]


def _parent(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, IndexError, ValueError):  # gone meanwhile
        return -1


def _collect_and_kill(cluster: str, out: Path, victims: Callable[[], list[int]]) -> int:
    """Collect 6 roll episodes on the cluster, SIGKILL the processes ``victims`` names as
    soon as it names any (an episode is running there), and return how many were killed."""
    argv = ["autopilot", "--task", "roll", "--episodes", "6", "--episode-time", "40"]
    command = [sys.executable, "-m", "gymfg_il.collect", *argv, "--out", str(out)]
    run = subprocess.Popen(
        [*command, "--no-progress", "--ray", cluster],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    killed: list[int] = []
    deadline = time.monotonic() + 120
    while not killed and run.poll() is None and time.monotonic() < deadline:
        for pid in victims():
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
        time.sleep(0.05)
    _stdout, stderr = run.communicate(timeout=600)
    assert killed, "no episode was seen running where it could be killed"
    assert run.returncode == 0, stderr[-2000:]
    return len(killed)


def _six_in_one_process(tmp_path: Path) -> bytes:
    argv = ["autopilot", "--task", "roll", "--episodes", "6", "--episode-time", "40"]
    assert collect.main([*argv, "--out", str(tmp_path / "one"), "--no-progress"]) == 0
    return _frames(tmp_path / "one")


def test_a_killed_worker_loses_nothing(cluster, tmp_path):
    def one_worker() -> list[int]:
        return _pids("ray::_seed_task")[:1]

    _collect_and_kill(cluster, tmp_path / "killed", one_worker)
    assert _frames(tmp_path / "killed") == _six_in_one_process(tmp_path)


def test_a_dead_node_loses_nothing(cluster, tmp_path):
    """A third node joins, and dies (its raylet and every worker on it, SIGKILL) while it
    flies an episode: its episodes are retried elsewhere and the dataset is unchanged."""
    _ray([RAY, "start", f"--address={cluster}", *NODE, '--resources={"doomed": 1}'])
    raylet = [
        p for p in _pids("raylet/raylet") if b"doomed" in Path(f"/proc/{p}/cmdline").read_bytes()
    ]
    assert len(raylet) == 1, f"the third node's raylet: {raylet}"

    def the_node() -> list[int]:
        busy = [p for p in _pids("ray::_seed_task") if _parent(p) == raylet[0]]
        return [raylet[0], *busy] if busy else []

    assert _collect_and_kill(cluster, tmp_path / "dead", the_node) >= 2
    assert _frames(tmp_path / "dead") == _six_in_one_process(tmp_path)
