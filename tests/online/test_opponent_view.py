"""What a team sees of the others: only the server's opponent view, by name, in its rows
and in its rewards. Real server processes, real sockets."""

import sys
from pathlib import Path

import numpy as np
import pytest
import zmq

from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import decode, encode

pytestmark = pytest.mark.network
sys.path.insert(0, str(Path(__file__).parent))
from waiting import wait_until  # noqa: E402


def test_a_team_receives_only_the_opponent_view(server):
    address, _ = server("--mode", "open", "--view", "altitude_ft", "heading_deg")
    ctx = zmq.Context.instance()
    socks = {}
    for team, callsign in (("red", "red-1"), ("blue", "blue-1")):
        socks[team] = ctx.socket(zmq.DEALER)
        socks[team].connect(address)
        socks[team].send(encode({"type": "join", "team": team, "aircraft": {callsign: "c172p"}}))
        assert decode(socks[team].recv(), "server")["type"] == "welcome"
    secret = [float(i) for i in range(26)]  # every variable distinct
    socks["blue"].send(encode({"type": "report", "team": "blue", "states": {"blue-1": [0.0] * 26}}))
    decode(socks["blue"].recv(), "server")  # blue alone: tick 0
    socks["red"].send(encode({"type": "report", "team": "red", "states": {"red-1": secret}}))

    def blue_sees_red():  # blue flies alone until red's report joins it to the lockstep
        socks["blue"].send(
            encode({"type": "report", "team": "blue", "states": {"blue-1": [0.0] * 26}})
        )
        central = decode(socks["blue"].recv(), "server")
        assert central["type"] == "central"
        return central["opponents"]

    opponents = wait_until(blue_sees_red, "red in blue's central state")
    assert opponents == [["red-1", "red", [2.0, 6.0]]]  # altitude, heading only
    for s in socks.values():
        s.close(0)


def test_reward_targets_read_the_view_the_server_announces(server):
    """A reward that reads an opponent sees the variables the server sends, by name, even
    when the server's view is not the default one."""
    import threading
    from functools import partial

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.sim.properties import INDEX
    from gymfg_il.tasks import DummyTask

    address, _ = server("--mode", "open", "--view", "heading_deg", "airspeed_kts")
    blue = zmq.Context.instance().socket(zmq.DEALER)
    blue.connect(address)
    blue.send(encode({"type": "join", "team": "blue", "aircraft": {"blue-1": "c172p"}}))
    assert decode(blue.recv(), "server")["type"] == "welcome"
    state = [0.0] * 26
    state[INDEX["heading_deg"]], state[INDEX["airspeed_kts"]] = 123.0, 98.0

    done = threading.Event()
    blue.setsockopt(zmq.RCVTIMEO, 10000)

    def fly_blue():  # reports until red has flown, so red always meets it in the lockstep
        while not done.is_set():
            blue.send(encode({"type": "report", "team": "blue", "states": {"blue-1": state}}))
            decode(blue.recv(), "server")

    thread = threading.Thread(target=fly_blue)
    thread.start()
    seen = []
    task = partial(
        DummyTask, reward=lambda ctx: seen.append(ctx.targets["blue-1"]["airspeed_kts"]) or 0.0
    )
    red_one = c172p("red-1")
    red = Team("red", [(red_one, task)], reward_function_targets={red_one: [c172p("blue-1")]})
    env = OnlineEnv(address, timeout_s=20)
    env.reset(red, seed=0)
    for _ in range(2):
        env.step(np.zeros(4))
    done.set()
    env.close()
    thread.join(20)
    blue.close(0)
    assert seen == [98.0, 98.0]
