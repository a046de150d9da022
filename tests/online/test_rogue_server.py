"""The client against a rogue server: a real ROUTER socket on loopback that answers the
client's join and report with malformed replies. Every one is a ``ServerError`` naming what
is wrong, never a raw KeyError/IndexError/TypeError/ValueError, and never accepted."""

import threading

import msgpack
import numpy as np
import pytest
import zmq

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import VERSION, ServerError, decode, encode
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW
from gymfg_il.tasks import DummyTask

pytestmark = pytest.mark.network

VIEW = list(DEFAULT_OPPONENT_VIEW)
WELCOME = {"type": "welcome", "team": "red", "mode": "open", "opponent_view": VIEW, "simulation": 0}
ROW = ["blue-1", "blue", [37.6, -122.4, 3000.0, 0.0, 1.0, 90.0]]
CENTRAL = {"type": "central", "tick": 0, "opponents": [ROW], "done": False, "reason": ""}


def raw(msg):
    return msgpack.packb(msg, use_bin_type=True)


def central(**changes):
    return encode({**CENTRAL, **changes})


def welcome(**changes):
    return encode({**WELCOME, **changes})


def without(msg, key):
    return encode({k: v for k, v in msg.items() if k != key})


# (what is wrong, the reply to join, the reply to the first report, a word the error names)
BAD_WELCOMES = {
    "welcome without opponent_view": (without(WELCOME, "opponent_view"), "opponent_view"),
    "opponent_view not a list": (welcome(opponent_view="lat_deg"), "opponent_view"),
    "opponent_view of unknown names": (welcome(opponent_view=["lat_deg", "secret"]), "secret"),
    "welcome for another team": (welcome(team="blue"), "blue"),
    "welcome with an unknown mode": (welcome(mode="chaos"), "chaos"),
    "simulation not an integer": (welcome(simulation="0"), "simulation"),
}
BAD_CENTRALS = {
    "central without opponents": (without(CENTRAL, "opponents"), "opponents"),
    "central without tick": (without(CENTRAL, "tick"), "tick"),
    "opponents not a list": (central(opponents={"blue-1": 1}), "opponents"),
    "a row of two entries": (central(opponents=[["blue-1", "blue"]]), "row"),
    "a row of the wrong width": (central(opponents=[["blue-1", "blue", [1.0, 2.0]]]), "6"),
    "a row holding NaN": (
        central(opponents=[["blue-1", "blue", [float("nan"), *ROW[2][1:]]]]),
        "nan",
    ),
    "a row holding a string": (central(opponents=[["blue-1", "blue", ["1", *ROW[2][1:]]]]), "'1'"),
    "a row holding a boolean": (
        central(opponents=[["blue-1", "blue", [True, *ROW[2][1:]]]]),
        "True",
    ),
    "a callsign with a newline": (central(opponents=[["blue\n1", "blue", ROW[2]]]), "callsign"),
    "a team name that is a number": (central(opponents=[["blue-1", 7, ROW[2]]]), "team"),
    "a callsign shown twice": (central(opponents=[ROW, ROW]), "twice"),
    "tick not an integer": (central(tick="1"), "tick"),
    "done not a boolean": (central(done="yes"), "done"),
    "reason not a string": (central(reason=5), "reason"),
    "an unknown type": (encode({"type": "surprise"}), "surprise"),
    "an error without a code": (encode({"type": "error", "message": "x"}), "code"),
    "an error whose message is a number": (
        encode({"type": "error", "code": "x", "message": 3}),
        "message",
    ),
    "a welcome where a central is due": (welcome(), "welcome"),
    "a reply without a version": (raw({k: v for k, v in CENTRAL.items()}), "version"),
    "a reply that is a list": (raw([VERSION, "central"]), "map"),
    "not msgpack at all": (b"\xc1\xc1\xc1", "msgpack"),
}


class RogueServer:
    """A ROUTER socket on loopback answering each join and report with the next canned
    reply (a tuple: several messages)."""

    def __init__(self, replies):
        self.ctx = zmq.Context()
        self.sock = self.ctx.socket(zmq.ROUTER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.setsockopt(zmq.RCVTIMEO, 100)
        port = self.sock.bind_to_random_port("tcp://127.0.0.1")
        self.address = f"tcp://127.0.0.1:{port}"
        self.replies = list(replies)
        self.seen = []
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.serve)
        self.thread.start()

    def serve(self):
        while not self.stop.is_set():
            try:
                identity, data = self.sock.recv_multipart()
            except zmq.Again:
                continue
            msg = decode(data, "client")
            self.seen.append(msg["type"])
            if msg["type"] in ("join", "report") and self.replies:
                reply = self.replies.pop(0)
                for data in reply if isinstance(reply, tuple) else (reply,):
                    self.sock.send_multipart([identity, data])

    def close(self):
        self.stop.set()
        self.thread.join(30)
        self.sock.close(0)
        self.ctx.term()


def red():
    return Team("red", [(c172p("red-1"), DummyTask)], episode_time_s=60)


def meet(replies):
    """Reset a client against the rogue server; what the reset raised (or returned)."""
    rogue = RogueServer(replies)
    env = OnlineEnv(rogue.address, timeout_s=20)
    try:
        return env.reset(red(), seed=0)
    finally:
        env.close()
        rogue.close()


def test_a_well_formed_exchange_is_accepted():
    _, opponents = meet([welcome(), central()])
    assert opponents.shape == (1, 6) and opponents[0][2] == 3000.0


@pytest.mark.parametrize("case", sorted(BAD_WELCOMES))
def test_a_malformed_welcome_is_a_server_error(case):
    reply, named = BAD_WELCOMES[case]
    with pytest.raises(ServerError) as err:
        meet([reply, central()])
    assert err.value.code == "malformed" and named.lower() in str(err.value).lower(), err.value


@pytest.mark.parametrize("case", sorted(BAD_CENTRALS))
def test_a_malformed_central_state_is_a_server_error(case):
    reply, named = BAD_CENTRALS[case]
    with pytest.raises(ServerError) as err:
        meet([welcome(), reply])
    assert err.value.code == "malformed" and named.lower() in str(err.value).lower(), err.value


def test_a_malformed_reply_mid_episode_is_a_server_error():
    rogue = RogueServer([welcome(), central(), central(opponents=[["blue-1", "blue", [1.0]]])])
    env = OnlineEnv(rogue.address, timeout_s=20)
    try:
        env.reset(red(), seed=0)
        with pytest.raises(ServerError, match="malformed"):
            env.step(np.zeros(4))
    finally:
        env.close()
        rogue.close()


def test_text_from_the_server_reaches_the_log_escaped(caplog):
    """A rogue server's wait reason or error message cannot forge log lines."""
    import logging

    caplog.set_level(logging.WARNING, logger="gymfg_il.online")
    forged = "ok\n2026-11-30 INFO forged line\x1b[2J"
    with pytest.raises(ServerError) as err:
        wait = encode({"type": "wait", "reason": forged})
        meet([(wait, encode({"type": "error", "code": "x", "message": forged}))])
    assert "\n" not in str(err.value) and "\x1b" not in str(err.value)
    assert "\n2026" not in caplog.text and "\x1b" not in caplog.text
    assert "forged line" in caplog.text  # said, escaped
