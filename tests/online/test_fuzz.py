"""Whatever a client sends, the server answers or stays silent and serves on: fuzzed
messages against a real server process."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
import zmq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import VERSION, decode

pytestmark = pytest.mark.network
sys.path.insert(0, str(Path(__file__).parent))
import run_team  # noqa: E402

ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    payload=st.one_of(
        st.binary(max_size=300),
        st.recursive(
            st.one_of(
                st.none(), st.booleans(), st.integers(-(2**63), 2**64 - 1), st.floats(), st.text()
            ),
            lambda inner: (
                st.lists(inner, max_size=4)
                | st.dictionaries(st.text(max_size=8), inner, max_size=4)
            ),
            max_leaves=12,
        ),
        st.fixed_dictionaries(
            {
                "v": st.just(VERSION),
                "type": st.sampled_from(["join", "report", "leave"]),
                "team": st.text(max_size=70),
                "states": st.dictionaries(
                    st.text(max_size=5), st.lists(st.floats(), max_size=27), max_size=3
                ),
            }
        ),
    )
)
def test_fuzzed_messages_never_crash_the_server(fuzz_server, payload):
    _address, sock = fuzz_server
    import msgpack

    data = payload if isinstance(payload, bytes) else msgpack.packb(payload, use_bin_type=True)
    sock.send(data)
    if sock.poll(2000):
        reply = decode(sock.recv(), "server")
        assert reply["type"] in ("error", "welcome", "central")


@pytest.fixture(scope="module")
def fuzz_server():
    proc = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.serve", "--mode", "open", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        env=ENV,
    )
    line = proc.stdout.readline()
    assert b"serving" in line
    address = line.decode().split()[-1]
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.connect(address)
    yield address, sock
    sock.close(0)
    # after all the garbage, a real team still flies
    teams = run_team.teams(1)
    env = OnlineEnv(address, timeout_s=10)
    states, _ = run_team.fly(env, teams["red"], 0)
    env.close()
    alive = proc.poll() is None
    proc.terminate()
    proc.wait(5)
    assert alive and len(states) == 10
