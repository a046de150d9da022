"""The online server against a red team: real server processes, real sockets."""

import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import zmq

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import ServerError, decode, encode
from gymfg_il.tasks import DummyTask

pytestmark = pytest.mark.network
ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


@pytest.fixture
def serve(tmp_path):
    """Start ``python -m gymfg_il.serve OPTIONS``; yields (address, process, stderr file)."""
    procs = []

    def start(*options, expect_serving=True):
        err = tmp_path / f"server{len(procs)}.err"
        proc = subprocess.Popen(
            [sys.executable, "-m", "gymfg_il.serve", "--port", "0", *options],
            stdout=subprocess.PIPE,
            stderr=open(err, "w"),  # noqa: SIM115 (the process owns it)
            env=ENV,
        )
        procs.append(proc)
        if not expect_serving:
            proc.wait(30)
            return None, proc, err
        line = proc.stdout.readline().decode()
        assert "serving" in line, err.read_text()
        return line.split()[-1], proc, err

    yield start
    for proc in procs:
        proc.terminate()
        proc.wait(5)


def team(name, seconds=60.0):
    return Team(name, [(c172p(f"{name}-1"), DummyTask)], episode_time_s=seconds)


def fly(address, name, steps, token="", out=None, timeout_s=20.0):
    env = OnlineEnv(address, token=token, timeout_s=timeout_s)
    try:
        env.reset(team(name), seed=0)
        for _ in range(steps):
            *_, terminated, truncated, _ = env.step(np.array([0.0, 0.0, 0.0, 0.7]))
            if terminated or truncated:
                break
        if out is not None:
            out[name] = env.world.steps
    finally:
        env.close()


def fly_together(address, names, steps):
    """Teams in lockstep, each in a thread of its own; their steps flown."""
    out = {}
    threads = [threading.Thread(target=fly, args=(address, n, steps, "", out)) for n in names]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    return out


def raw_join(sock, name, token=""):
    sock.send(
        encode({"type": "join", "team": name, "token": token, "aircraft": {f"{name}-1": "c172p"}})
    )
    return decode(sock.recv(), "server")


def test_a_team_without_a_secret_cannot_join_a_server_with_secrets(serve):
    address, *_ = serve("--mode", "open", "--team", "red:r3d", "--team", "blue:blu3")
    for name, token in (("green", ""), ("green", "r3d"), ("red", ""), ("red", "blu3")):
        with pytest.raises(ServerError, match="unauthorised"):
            fly(address, name, 1, token)
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.RCVTIMEO, 5000)
    sock.connect(address)
    reply = raw_join(sock, "green")
    assert reply["type"] == "error" and "not on this server's list" in reply["message"]
    sock.close(0)
    ctx.term()
    out = {}
    fly(address, "red", 3, "r3d", out)  # the listed team, with its secret
    assert out == {"red": 3}


def test_a_server_without_secrets_says_so_and_stays_on_loopback(serve):
    _, proc, err = serve("--bind", "0.0.0.0", expect_serving=False)
    assert proc.returncode == 2 and "--insecure" in err.read_text()
    address, _, err = serve()
    time.sleep(0.5)
    assert "no secrets given" in err.read_text() and "127.0.0.1" in address
    address, *_ = serve("--bind", "0.0.0.0", "--insecure")
    assert address.startswith("tcp://0.0.0.0:")


def test_fixed_slots_are_freed_and_every_simulation_takes_new_teams(serve):
    address, *_ = serve("--mode", "fixed", "--teams", "2", "--timeout", "1")
    ctx = zmq.Context()
    squatters = [ctx.socket(zmq.DEALER) for _ in range(2)]
    for i, sock in enumerate(squatters):
        sock.setsockopt(zmq.RCVTIMEO, 5000)
        sock.connect(address)
        assert raw_join(sock, f"squat{i}")["type"] == "welcome"  # and never report
    third = ctx.socket(zmq.DEALER)
    third.setsockopt(zmq.RCVTIMEO, 5000)
    third.connect(address)
    assert raw_join(third, "red")["code"] == "full"
    time.sleep(2.0)  # the squatters' slots are freed after the 1 s timeout
    assert fly_together(address, ["red", "blue"], 5) == {"red": 5, "blue": 5}
    # red completes (its episode ends): the simulation ends and the roster with it
    assert fly_together(address, ["green", "yellow"], 5) == {"green": 5, "yellow": 5}
    for sock in [*squatters, third]:
        sock.close(0)
    ctx.term()


def test_a_join_flood_is_bounded_and_its_refusals_summarised(serve):
    address, proc, err = serve("--mode", "open", "--max-teams", "8", "--timeout", "2")

    def rss_kb():
        status = Path(f"/proc/{proc.pid}/status").read_text()
        return int(re.search(r"VmRSS:\s+(\d+)", status).group(1))

    before = rss_kb()
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.RCVTIMEO, 5000)
    sock.connect(address)
    started = time.monotonic()
    replies = [raw_join(sock, f"flood{i}") for i in range(2000)]
    # 8 at a time; a team that never reports frees its slot after the 2 s timeout
    admitted = 8 * (1 + int((time.monotonic() - started) // 2))
    codes = [r.get("code") for r in replies]
    assert 8 <= codes.count(None) <= admitted and codes.count("full") == 2000 - codes.count(None)
    assert rss_kb() - before < 20_000  # kB: the roster holds 8 teams, not 2000
    time.sleep(2.5)  # the flood's teams never reported: their slots are free again
    out = {}
    fly(address, "legit", 3, out=out)
    assert out == {"legit": 3}
    time.sleep(max(0.0, 10.5 - (time.monotonic() - started)))  # the log's window closes
    sock.send(b"not msgpack")
    decode(sock.recv(), "server")
    time.sleep(0.3)
    log = err.read_text()
    assert log.count("refused a message") <= 6
    assert re.search(r"refused \d+ more messages in the last \d+ s \(full: \d+\)", log)
    sock.close(0)
    ctx.term()


def test_a_team_waiting_for_the_others_hears_why_instead_of_timing_out(serve, caplog):
    import logging

    address, *_ = serve("--mode", "fixed", "--teams", "2")
    out = {}
    caplog.set_level(logging.WARNING, logger="gymfg_il.online.client")
    # red gives up after 1.5 s of silence, and waits 3.5 s for blue: the server's wait
    # messages (every half second) keep it waiting, and say what for
    first = threading.Thread(target=fly, args=(address, "red", 3, "", out, 1.5))
    first.start()
    time.sleep(3.5)
    assert "waiting for 1 more team to join" in caplog.text and out == {}
    fly(address, "blue", 3, "", out)
    first.join(30)
    assert out == {"red": 3, "blue": 3}
