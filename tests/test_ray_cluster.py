"""Collection and evaluation on a real two-node Ray cluster on this machine (a head and a
second node, started with `ray start`): identical to one process, also when a worker running
an episode is killed, and when a whole node dies mid-run.

The cluster keeps to itself: token authentication with a token of its own
(``RAY_AUTH_TOKEN_PATH``) and a temp folder of its own, and every process that joins or drives
it (the nodes, the collect and eval runs) starts with those settings. A ``~/.ray/auth_token``
that appears while the tests run (any Ray use on the machine makes one; it once failed the
second ``ray start``) or another cluster on the machine changes nothing, and only this
cluster's processes are stopped. Every wait is on a condition, with a deadline that grows with
the machine's load (busy loops beside the tests are normal)."""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from gymfg_il import collect
from gymfg_il import eval as evaluate

if importlib.util.find_spec("ray") is None:  # not imported here: only the cluster's processes
    pytest.skip("needs Ray: pip install -e '.[ray]'", allow_module_level=True)
pytestmark = pytest.mark.ray
RAY = str(Path(sys.executable).parent / "ray")
NODE = ["--num-cpus=1", "--disable-usage-stats"]


def slowness() -> float:
    """How much slower than an idle machine this one is now (runnable processes per core)."""
    return max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))


def wait_for(condition: Callable[[], object], seconds: float, what: str, poll: float = 0.5):
    """``condition()``'s first true value; ``seconds`` on an idle machine, more under load."""
    deadline = time.monotonic() + seconds * slowness()
    while not (found := condition()):
        assert time.monotonic() < deadline, f"{what} (waited {seconds * slowness():.0f} s)"
        time.sleep(poll)
    return found


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _processes() -> dict[int, tuple[int, bytes]]:
    """pid -> (parent pid, command line) of every live process now (zombies are done)."""
    found = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                state, parent = (entry / "stat").read_text().rsplit(")", 1)[1].split()[:2]
                cmdline = (entry / "cmdline").read_bytes()
            except OSError:  # gone meanwhile
                continue
            if state != "Z":
                found[int(entry.name)] = (int(parent), cmdline)
    return found


class Cluster:
    """A Ray cluster of this test module: its address, its settings, its processes."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.address = f"127.0.0.1:{_free_port()}"
        token = folder / "auth_token"
        token.write_text(secrets.token_hex(32))
        token.chmod(0o600)
        self.env = {
            **os.environ,
            "RAY_AUTH_MODE": "token",
            "RAY_AUTH_TOKEN_PATH": str(token),
            "RAY_USAGE_STATS_ENABLED": "0",
            "RAY_worker_niceness": "0",
            "HF_HUB_OFFLINE": "1",
        }
        for other in ("RAY_AUTH_TOKEN", "RAY_ADDRESS"):
            self.env.pop(other, None)

    def ray(self, *argv: str) -> None:
        done = subprocess.run(
            [RAY, *argv],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=180 * slowness(),
        )
        assert done.returncode == 0, f"ray {' '.join(argv[:2])} failed:\n{done.stderr[-3000:]}"

    def alive_nodes(self) -> int:
        script = (
            f"import ray; ray.init(address={self.address!r}, log_to_driver=False, "
            "logging_level='ERROR'); print(sum(n['Alive'] for n in ray.nodes()))"
        )
        done = subprocess.run(
            [sys.executable, "-c", script],
            env=self.env,
            capture_output=True,
            text=True,
            timeout=180 * slowness(),
        )
        last = done.stdout.split()[-1:] if done.returncode == 0 else []
        return int(last[0]) if last and last[0].isdigit() else 0

    def wait_nodes(self, n: int) -> None:
        wait_for(lambda: self.alive_nodes() >= n, 60, f"{n} nodes never joined", poll=1.0)

    def own(self, processes: dict[int, tuple[int, bytes]]) -> set[int]:
        """This cluster's processes: those started with its folder, and theirs."""
        mine = {p for p, (_, cmd) in processes.items() if str(self.folder).encode() in cmd}
        grown = True
        while grown:
            children = {p for p, (parent, _) in processes.items() if parent in mine}
            grown = not children <= mine
            mine |= children
        return mine - {os.getpid()}

    def raylets(self, mark: bytes = b"") -> list[int]:
        processes = _processes()
        return [
            p
            for p in self.own(processes)
            if b"raylet/raylet" in processes[p][1] and mark in processes[p][1]
        ]

    def busy_workers(self, raylets: list[int]) -> list[int]:
        """Workers of these raylets flying an episode now."""
        return [
            p
            for p, (parent, cmd) in _processes().items()
            if parent in raylets and cmd.startswith(b"ray::_seed_task")
        ]

    def stop(self) -> None:
        """Stop this cluster's processes, and no other (``ray stop`` would stop every
        cluster on the machine)."""
        mine = self.own(_processes())
        for sig in (signal.SIGTERM, signal.SIGKILL):  # the second for what outlived the first
            for pid in mine & set(_processes()):
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, sig)
            deadline = time.monotonic() + 30 * slowness()
            while mine & set(_processes()) and time.monotonic() < deadline:
                time.sleep(0.5)


@pytest.fixture(scope="module")
def cluster():
    # short: Ray's socket paths inside it must stay under the 107-byte limit
    folder = Path(tempfile.mkdtemp(prefix="gymfg-ray-", dir="/tmp"))
    cluster = Cluster(folder)
    try:
        port = cluster.address.rsplit(":", 1)[1]
        cluster.ray(
            "start", "--head", f"--port={port}", "--include-dashboard=false",
            f"--temp-dir={folder}", *NODE,
        )  # fmt: skip
        cluster.ray("start", f"--address={cluster.address}", *NODE)
        cluster.wait_nodes(2)
        yield cluster
    finally:
        cluster.stop()
        shutil.rmtree(folder, ignore_errors=True)


def _collect_on(cluster: Cluster, out: Path, *argv: str) -> subprocess.Popen[str]:
    command = [sys.executable, "-m", "gymfg_il.collect", "autopilot", *argv]
    return subprocess.Popen(
        [*command, "--out", str(out), "--no-progress", "--ray", cluster.address],
        env=cluster.env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _finish(run: subprocess.Popen[str]) -> None:
    _stdout, stderr = run.communicate(timeout=600 * slowness())
    assert run.returncode == 0, stderr[-3000:]


def _frames(out: Path) -> bytes:
    return (out / "dataset/data/chunk-000/file-000.parquet").read_bytes()


ROLL4 = ("--task", "roll", "--episodes", "4", "--episode-time", "10")


def test_collection_on_the_cluster_is_identical_to_one_process(cluster, tmp_path):
    _finish(_collect_on(cluster, tmp_path / "ray", *ROLL4))
    assert collect.main(["autopilot", *ROLL4, "--out", str(tmp_path / "one"), "--no-progress"]) == 0
    assert _frames(tmp_path / "ray") == _frames(tmp_path / "one")


def test_eval_rows_on_the_cluster_match_one_process(cluster, tmp_path):
    argv = ["--task", "roll", "--episodes", "3", "--episode-time", "10", "--no-progress"]
    command = [sys.executable, "-m", "gymfg_il.eval", *argv, "--ray", cluster.address]
    done = subprocess.run(
        [*command, "--json", str(tmp_path / "r.json")],
        env=cluster.env,
        capture_output=True,
        text=True,
        timeout=600 * slowness(),
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert evaluate.main([*argv, "--json", str(tmp_path / "o.json")]) == 0
    assert json.loads((tmp_path / "r.json").read_text()) == json.loads(
        (tmp_path / "o.json").read_text()
    )


ROLL6 = ("--task", "roll", "--episodes", "6", "--episode-time", "40")


def _collect_and_kill(cluster: Cluster, out: Path, victims: Callable[[], list[int]]) -> int:
    """Collect 6 roll episodes on the cluster, SIGKILL the processes ``victims`` names as
    soon as it names any (an episode is running there), and return how many were killed."""
    run = _collect_on(cluster, out, *ROLL6)
    killed: list[int] = []

    def kill() -> bool:
        for pid in victims():
            try:
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            except ProcessLookupError:
                pass
        return bool(killed) or run.poll() is not None

    wait_for(kill, 120, "no episode was seen running where it could be killed", poll=0.02)
    _finish(run)
    assert killed, "the collection ended before an episode was seen running"
    return len(killed)


def _six_in_one_process(tmp_path: Path) -> bytes:
    assert collect.main(["autopilot", *ROLL6, "--out", str(tmp_path / "one"), "--no-progress"]) == 0
    return _frames(tmp_path / "one")


def test_a_killed_worker_loses_nothing(cluster, tmp_path):
    def one_worker() -> list[int]:
        return cluster.busy_workers(cluster.raylets())[:1]

    _collect_and_kill(cluster, tmp_path / "killed", one_worker)
    assert _frames(tmp_path / "killed") == _six_in_one_process(tmp_path)


def test_a_dead_node_loses_nothing(cluster, tmp_path):
    """A third node joins, and dies (its raylet and every worker on it, SIGKILL) while it
    flies an episode: its episodes are retried elsewhere and the dataset is unchanged."""
    cluster.ray("start", f"--address={cluster.address}", *NODE, '--resources={"doomed": 1}')
    cluster.wait_nodes(3)
    raylet = cluster.raylets(b"doomed")
    assert len(raylet) == 1, f"the third node's raylet: {raylet}"

    def the_node() -> list[int]:
        busy = cluster.busy_workers(raylet)
        return [*raylet, *busy] if busy else []

    assert _collect_and_kill(cluster, tmp_path / "dead", the_node) >= 2
    assert _frames(tmp_path / "dead") == _six_in_one_process(tmp_path)


def test_a_driver_without_the_clusters_token_is_told_so(cluster, tmp_path):
    wrong = tmp_path / "wrong_token"
    wrong.write_text(secrets.token_hex(32))
    argv = ["autopilot", "--episodes", "1", "--out", str(tmp_path / "o"), "--ray", cluster.address]
    done = subprocess.run(
        [sys.executable, "-m", "gymfg_il.collect", *argv, "--no-progress"],
        env={**cluster.env, "RAY_AUTH_TOKEN_PATH": str(wrong)},
        capture_output=True,
        text=True,
        timeout=300 * slowness(),
    )
    assert done.returncode == 2, done.stderr[-3000:]
    assert (
        f"error: --ray {cluster.address}: the cluster refused this process's token" in done.stderr
    )
    assert "Traceback" not in done.stderr
