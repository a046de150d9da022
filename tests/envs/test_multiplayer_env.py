"""FlightGear aircraft heard over multiplayer are opponents of the offline env, without a
FlightGear: a sender on this machine plays FlightGear's part
(``tests/flightgear/test_flightgear_mp.py`` does the same against a real one)."""

import socket
import time

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.envs import OfflineEnv
from gymfg_il.errors import ConfigError
from gymfg_il.flightgear import multiplayer as mp
from gymfg_il.flightgear import peers
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.tasks import DummyTask

pytestmark = pytest.mark.network


PERSON = (37.62, -122.37, 3000.0, 20.0, 3.0, 280.0)


def test_a_flightgear_aircraft_is_an_opponent_and_a_reward_target_until_it_falls_silent(
    free_udp_ports,
):
    listen, fg_in = free_udp_ports(2)
    seen = []

    def note_person(ctx):  # what the reward sees of the person: their pose, or None
        view = ctx.targets.get("person")
        seen.append(None if view is None else view.values.copy())
        return 0.0

    team = Team(
        "blue",
        [(c172p("ego"), DummyTask(reward=note_person))],
        reward_function_targets={c172p("ego"): [c172p("person")]},
    )
    config = MultiplayerConfig(listen_port=listen, send_to=[("127.0.0.1", fg_in)], timeout_s=0.5)
    fg = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # FlightGear's --multiplay=in
    fg.bind(("127.0.0.1", fg_in))
    fg.settimeout(5)
    person = mp.TrafficSender([listen])
    env = OfflineEnv(agent_hz=30, multiplayer=config)
    try:
        env.configure(team)  # the env listens from here on
        person.send("person", "c172p", PERSON)  # on loopback, queued at the listener on send
        _, rows = env.reset(team, seed=0)
        assert rows.shape == (1, 6)
        assert rows[0] == pytest.approx(PERSON, abs=1e-4)
        # our aircraft reaches FlightGear as multiplayer traffic
        heard = peers.decode(fg.recv(4096))
        assert heard.callsign == "ego" and heard.model.endswith("c172p.xml")
        action = np.array([0.0, 0.0, 0.0, 0.7])
        t0 = time.perf_counter()
        for _ in range(9):
            person.send("person", "c172p", PERSON)
            _, rows, rewards, _, _, info = env.step(action)
            assert info["opponent_callsigns"] == ["person"]
        # paced to the wall clock: 9 steps at 30 Hz never take less than 0.3 s (the upper
        # side is the machine's load, not the env's)
        assert time.perf_counter() - t0 > 0.25
        assert seen[-1] is not None and seen[-1] == pytest.approx(PERSON, abs=1e-4)
        for _ in range(30):  # 1 s of silence: dropped after 0.5 s
            _, rows, rewards, *_, info = env.step(action)
        assert rows.shape == (0, 6) and info["opponent_callsigns"] == []
        assert seen[-1] is None and np.isfinite(rewards).all()
    finally:
        env.close()
        person.close()
        fg.close()


def test_flightgear_opponents_show_only_position_and_orientation(free_udp_ports):
    with pytest.raises(ConfigError, match="FlightGear aircraft show only"):
        OfflineEnv(
            multiplayer=MultiplayerConfig(listen_port=free_udp_ports(1)[0]),
            opponent_view=("lat_deg", "lon_deg", "airspeed_kts"),
        )


def test_a_taken_port_is_a_config_error_naming_it(free_udp_ports):
    port = free_udp_ports(1)[0]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", port))
        env = OfflineEnv(multiplayer=MultiplayerConfig(listen_port=port))
        with pytest.raises(ConfigError, match=f"127.0.0.1:{port}"):
            env.configure(Team("blue", [(c172p("ego"), DummyTask)]))


def test_the_pettingzoo_env_shows_flightgear_aircraft_to_every_team_until_they_fall_silent(
    free_udp_ports,
):
    from pettingzoo.test import parallel_api_test

    from gymfg_il.aircraft import f15
    from gymfg_il.envs import parallel_env

    listen, fg_in = free_udp_ports(2)
    seen = []

    def note_person(ctx):
        view = ctx.targets.get("person")
        seen.append(None if view is None else view.values.copy())
        return 0.0

    red1_ = f15("red1")
    red = Team(
        "red",
        [(red1_, DummyTask(reward=note_person))],
        reward_function_targets={red1_: [c172p("person")]},
    )
    blue = Team("blue", [(c172p("blue1"), DummyTask)])
    config = MultiplayerConfig(listen_port=listen, send_to=[("127.0.0.1", fg_in)], timeout_s=0.5)
    fg = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    fg.bind(("127.0.0.1", fg_in))
    fg.settimeout(5)
    person = mp.TrafficSender([listen])
    # callsigns of 7 characters at most: FlightGear keeps no more
    env = parallel_env([red, blue], agent_hz=30, multiplayer=config)  # listens from here on
    try:
        person.send("person", "c172p", PERSON)  # on loopback, queued at the listener on send
        obs, infos = env.reset(seed=0)
        for agent, other in (("red1", "blue1"), ("blue1", "red1")):
            assert obs[agent]["opponents"].shape == (2, 6)  # the other team, then the person
            assert obs[agent]["opponents"][1] == pytest.approx(PERSON, abs=1e-4)
            assert obs[agent] in env.observation_space(agent)
            assert infos[agent]["opponent_callsigns"] == [other, "person"]
        assert {peers.decode(fg.recv(4096)).callsign for _ in range(2)} == {"red1", "blue1"}
        action = np.array([0.0, 0.0, 0.0, 0.7])
        t0 = time.perf_counter()
        for _ in range(9):
            person.send("person", "c172p", PERSON)
            obs, rewards, *_, infos = env.step(dict.fromkeys(env.agents, action))
            assert infos["blue1"]["opponent_callsigns"] == ["red1", "person"]
        assert time.perf_counter() - t0 > 0.25  # paced to the wall clock (9 steps at 30 Hz)
        assert seen[-1] == pytest.approx(PERSON, abs=1e-4)
        for _ in range(30):  # 1 s of silence: dropped after 0.5 s
            obs, rewards, *_, infos = env.step(dict.fromkeys(env.agents, action))
        assert obs["blue1"]["opponents"].shape == (1, 6)
        assert obs["blue1"] in env.observation_space("blue1")
        assert infos["red1"]["opponent_callsigns"] == ["blue1"]
        assert seen[-1] is None and all(np.isfinite(r) for r in rewards.values())
        person.send("person", "c172p", PERSON)  # heard again: PettingZoo's own checks pass
        parallel_api_test(env, num_cycles=20)
    finally:
        env.close()
        person.close()
        fg.close()
