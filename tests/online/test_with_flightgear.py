"""An online team and FlightGear: its views show its opponents as multiplayer traffic, and the
FlightGear aircraft its client hears are its own opponents, never relayed to other teams. A
sender on this machine plays FlightGear's part."""

import socket
import struct
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.online.client import OnlineEnv

pytestmark = pytest.mark.network
sys.path.insert(0, str(Path(__file__).parent))
import run_team  # noqa: E402


def test_a_teams_views_show_its_opponents_as_traffic(server, tmp_path):
    """Every opponent the server lets the team see reaches the team's FlightGear view as
    multiplayer traffic, with the position the team received; the viewer itself does not."""
    from gymfg_il.flightgear import multiplayer as mp

    address, _ = server("--mode", "fixed", "--teams", "2")
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for port in range(23000, 32000):
        try:
            rx.bind(("127.0.0.1", port))
            break
        except OSError:
            continue
    rx.settimeout(10)
    blue = run_team.start(address, "", "blue", 0, 3, tmp_path / "blue.npy")
    env = OnlineEnv(address, timeout_s=20, traffic={"red-1": [rx.getsockname()[1]]})
    _, opponents = env.reset(run_team.teams(3)["red"], seed=0)
    for _ in range(5):
        _, opponents, *_ = env.step(np.zeros(8))
    env.close()
    blue.wait(30)
    packets = {}
    rx.setblocking(False)
    while True:
        try:
            data = rx.recv(1024)
        except BlockingIOError:
            break
        callsign = mp.HEADER.unpack_from(data)[-1].rstrip(b"\0").decode()
        packets[callsign] = struct.unpack_from(">3d", data, mp.HEADER.size + 96 + 16)
    rx.close()
    assert set(packets) == {"red-2", "blue-1"}  # teammate and opponent, not the viewer
    lat, lon, alt = opponents[0][:3]  # what the team saw of blue-1 (the view before the end)
    assert np.allclose(packets["blue-1"], mp.ecef(lat, lon, alt), atol=200)


def test_a_client_with_multiplayer_shows_flightgear_aircraft_to_its_team_alone(
    server, free_udp_ports
):
    """A team's client hears FlightGear on its own port: the person follows the server's
    rows and is a reward target until silent; the server relays nothing of them to the
    other team. A sender on this machine plays FlightGear's part."""
    import threading

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.flightgear import multiplayer as mp
    from gymfg_il.flightgear import peers
    from gymfg_il.flightgear.peers import MultiplayerConfig
    from gymfg_il.tasks import DummyTask

    person_pose = (37.62, -122.37, 3000.0, 20.0, 3.0, 280.0)
    listen, fg_in = free_udp_ports(2)
    address, _ = server("--mode", "open", "--timeout", "60")
    fg = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # FlightGear's --multiplay=in
    fg.bind(("127.0.0.1", fg_in))
    fg.settimeout(5)
    person = mp.TrafficSender([listen])
    flying = threading.Event()
    flying.set()

    def fly_person():  # FlightGear sends ~50 times a second while the person flies
        while flying.is_set():
            person.send("person", "c172p", person_pose)
            time.sleep(0.02)

    blue_saw: list[list[str]] = []
    blue = OnlineEnv(address, timeout_s=5)
    blue.reset(Team("blue", [(c172p("blue1"), DummyTask)], episode_time_s=1e4), seed=1)

    def fly_blue():  # until it has met red for 10 steps, then leave
        while len([s for s in blue_saw if "red1" in s]) < 10:
            blue_saw.append(blue.step(np.zeros(4))[5]["opponent_callsigns"])
        blue.close()

    seen = []

    def note_person(ctx):
        view = ctx.targets.get("person")
        seen.append(None if view is None else view.values.copy())
        return 0.0

    red1 = c172p("red1")
    red = Team(
        "red",
        [(red1, DummyTask(reward=note_person))],
        reward_function_targets={red1: [c172p("person")]},
        episode_time_s=1e4,
    )
    config = MultiplayerConfig(listen_port=listen, send_to=[("127.0.0.1", fg_in)], timeout_s=0.5)
    red_env = OnlineEnv(address, timeout_s=5, agent_hz=30, multiplayer=config)
    threads = [threading.Thread(target=fly_person), threading.Thread(target=fly_blue)]
    try:
        for thread in threads:  # blue flies on: red joins the lockstep at a step boundary
            thread.start()
        red_env.reset(red, seed=0)
        both = None  # what red saw while blue and the person were both there
        for _ in range(90):  # in lockstep with blue until it leaves (after 10 steps with red)
            _, rows, rewards, _, _, info = red_env.step(np.zeros(4))
            if both is None and info["opponent_callsigns"] == ["blue1", "person"]:
                both = rows, seen[-1]
            if both is not None and "blue1" not in info["opponent_callsigns"]:
                break
        assert both is not None  # the server's row, then FlightGear's
        rows, target = both
        assert rows.shape == (2, 6) and rows[1] == pytest.approx(person_pose, abs=1e-4)
        assert target == pytest.approx(person_pose, abs=1e-4)
        assert info["opponent_callsigns"] == ["person"]  # blue left; the person flies on
        assert peers.decode(fg.recv(4096)).callsign == "red1"  # our aircraft reaches FlightGear
        threads[1].join(10)
        flying.clear()
        threads[0].join(5)
        for _ in range(30):  # 1 s of silence: dropped after 0.5 s
            _, rows, rewards, _, _, info = red_env.step(np.zeros(4))
        assert info["opponent_callsigns"] == [] and rows.shape == (0, 6)
        assert seen[-1] is None and np.isfinite(rewards).all()
    finally:
        flying.clear()
        for thread in threads:
            if thread.is_alive():
                thread.join(10)
        red_env.close()
        person.close()
        fg.close()
    assert any("red1" in s for s in blue_saw)
    assert not any("person" in s for s in blue_saw)  # not relayed to the other team


def test_multiplayer_needs_a_server_view_flightgear_aircraft_can_fill(server, free_udp_ports):
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.flightgear.peers import MultiplayerConfig
    from gymfg_il.tasks import DummyTask

    address, _ = server("--mode", "open", "--view", "altitude_ft", "airspeed_kts")
    env = OnlineEnv(
        address, timeout_s=5, multiplayer=MultiplayerConfig(listen_port=free_udp_ports(1)[0])
    )
    try:
        with pytest.raises(ConfigError, match=r"\['airspeed_kts'\]"):
            env.reset(Team("red", [(c172p("red1"), DummyTask)]), seed=0)
    finally:
        env.close()
