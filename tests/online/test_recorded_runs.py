"""An online team's run is recorded like an offline one and replays bit for bit, its rewards on
opponents from the views the team saw."""

import sys
from pathlib import Path

import numpy as np
import pytest

from gymfg_il.online.client import OnlineEnv

pytestmark = pytest.mark.network
sys.path.insert(0, str(Path(__file__).parent))
import run_team  # noqa: E402


def test_an_online_team_run_is_recorded_and_replays_bit_for_bit(server, tmp_path):
    from gymfg_il.recording.reader import read_log
    from gymfg_il.recording.recorder import Recorder
    from gymfg_il.recording.replay import replay_episode

    address, _ = server("--mode", "fixed", "--teams", "2")
    blue = run_team.start(address, "", "blue", 5, 3, tmp_path / "blue.npy")
    env = Recorder(OnlineEnv(address, timeout_s=20), tmp_path / "red", source="online")
    states, _ = run_team.fly(env, run_team.teams(3)["red"], 5)
    env.close()
    assert blue.wait(60) == 0
    log = read_log(next((tmp_path / "red" / "logs").glob("*.mcap")))
    assert log.session["online"] and [a.callsign for a in log.spec.aircraft_specs] == [
        "red-1",
        "red-2",
    ]
    (ep,) = log.complete_episodes
    assert np.array_equal(ep.steps["red-1"].state, states[:, 0])
    saw = ep.views("red")
    assert len(saw) == 30 and saw[-1].callsigns == ["blue-1"] and saw[-1].values.shape == (1, 6)
    blue_states = np.load(tmp_path / "blue.npy")
    from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, indices

    assert np.array_equal(saw[-1].values[0], blue_states[-1, 0][indices(DEFAULT_OPPONENT_VIEW)])
    assert replay_episode(log, ep).identical


def test_an_online_reward_on_an_opponent_replays_from_the_views_the_team_saw(server, tmp_path):
    from gymfg_il.aircraft import c172p, f15
    from gymfg_il.envs import Team
    from gymfg_il.recording.reader import read_log
    from gymfg_il.recording.recorder import Recorder
    from gymfg_il.recording.replay import replay_episode

    address, _ = server("--mode", "fixed", "--teams", "2")
    blue = run_team.start(address, "", "blue", 5, 3, tmp_path / "blue.npy")
    red = Team(
        "red",
        [(c172p("red-1"), run_team.ChaseTask)],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=3,
    )
    env = Recorder(OnlineEnv(address, timeout_s=20), tmp_path / "red")
    run_team.fly(env, red, 5)
    env.close()
    assert blue.wait(60) == 0
    log = read_log(next((tmp_path / "red" / "logs").glob("*.mcap")))
    assert log.spec.external_callsigns() == ["blue-1"]
    (ep,) = log.complete_episodes
    rewards = ep.steps["red-1"].reward
    assert np.isfinite(rewards).all() and rewards.std() > 0  # blue's distance moved
    assert replay_episode(log, ep).identical  # states and rewards, from the logged views
