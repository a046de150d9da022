"""A two-team run driven by hand, recorded, replayed bit for bit, and turned into a dataset
with one episode per aircraft."""

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.agent import RandomAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.collectors.commands import recover, replay
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs import OfflineEnv
from gymfg_il.envs.scenarios import head_on_merge
from gymfg_il.recording.reader import read_log
from gymfg_il.recording.recorder import Recorder
from gymfg_il.recording.replay import replay_episode
from gymfg_il.tasks import DummyTask, ReachStaticTargetAltitudeTask


@pytest.fixture(scope="module")
def team_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("teams")
    red = Team(
        "red",
        [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in (1, 2)],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=6,
    )  # fmt: skip
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetAltitudeTask)])
    env = OfflineEnv(opponents=[(blue, [RandomAgent(0.2, 0.8)])], scenario=head_on_merge())
    env = Recorder(env, out, source="dogfight")
    pilots = [RandomAgent(0.3), RandomAgent(0.1)]
    for seed in (5, 6):
        team_state, _ = env.reset(red, seed=seed)
        autopilot = controller_for(env.world.slots[0].task, "c172p", env.dt)
        autopilot.reset(seed)
        for p in pilots:
            p.reset(seed)
        done = False
        while not done:
            actions = [autopilot.act(team_state[0]), pilots[1].act(team_state[1])]
            team_state, _, _, terminated, truncated, _ = env.step(np.hstack(actions))
            done = terminated or truncated
    log_path = env.log
    env.close()
    return out, log_path


def test_every_aircraft_and_each_teams_view_is_logged(team_run):
    _, path = team_run
    log = read_log(path)
    assert log.finished and len(log.complete_episodes) == 2
    assert log.spec.teams[0].name == "red" and len(log.spec.aircraft_specs) == 3
    assert log.spec.scenario["name"] == "head_on_merge"
    ep = log.complete_episodes[0]
    assert list(ep.steps) == ["red-1", "red-2", "blue-1"]
    assert all(len(s) == 60 for s in ep.steps.values())
    blue_saw, red_saw = ep.views("blue"), ep.views("red")
    assert len(blue_saw) == len(red_saw) == 60
    assert blue_saw[0].callsigns == ["red-1", "red-2"] and red_saw[0].callsigns == ["blue-1"]
    view = log.spec.opponent_view
    assert blue_saw[-1].names == view
    # what red saw of blue after the last step is blue's position and orientation then
    from gymfg_il.sim.properties import indices

    last_blue = ep.steps["blue-1"].state[-1]
    assert np.array_equal(red_saw[-1].values[0], last_blue[indices(view)])
    assert ep.start["seed"] == 5 and ep.end["outcome"] == "time limit"


def test_a_team_run_replays_bit_for_bit(team_run, capsys):
    out, path = team_run
    log = read_log(path)
    for ep in log.complete_episodes:
        result = replay_episode(log, ep)
        assert result.identical and result.max_abs_diff == 0.0
        assert set(result.per_aircraft) == {"red-1", "red-2", "blue-1"}
    ep = log.complete_episodes[1]
    ep.steps["blue-1"].action[30, 0] += 0.2  # not what blue flew
    result = replay_episode(log, ep)
    assert not result.identical and result.per_aircraft["blue-1"] == (False, 30)
    assert result.per_aircraft["red-1"] == (True, None)  # red flies on regardless
    assert replay(out, None) == 0
    assert capsys.readouterr().out.count("identical") == 6


def test_each_aircraft_becomes_an_episode_that_stock_lerobot_opens(team_run):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    out, _ = team_run
    assert recover(out) == 0
    ds = LeRobotDataset("x/y", root=out / "dataset")
    assert ds.num_episodes == 6 and len(ds) == 360
    meta = ds.meta.episodes
    assert list(meta["gymfg/callsign"]) == ["red-1", "red-2", "blue-1"] * 2
    assert list(meta["gymfg/team"]) == ["red", "red", "blue"] * 2
    assert list(meta["gymfg/aircraft"]) == ["c172p", "c172p", "f15"] * 2
    assert list(meta["gymfg/source"]) == ["dogfight"] * 6
    log = read_log(next((out / "logs").glob("*.mcap")))
    blue = log.complete_episodes[1].steps["blue-1"]
    frame = ds[5 * 60 + 17]  # episode 5 is blue's second
    observed = blue.observation[17].astype(np.float32)
    assert np.array_equal(frame["observation.state"].numpy(), observed)
    assert np.array_equal(frame["action"].numpy(), blue.label[17].astype(np.float32))


def test_a_run_whose_tasks_the_record_cannot_rebuild_replays_with_them(tmp_path):
    def team():
        return Team("ego", [(c172p("ego"), DummyTask(reward=lambda ctx: 1.0))], episode_time_s=2)

    env = Recorder(OfflineEnv(), tmp_path)
    env.reset(team(), seed=3)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(np.array([0.05, -0.02, 0.0, 0.7]))
        done = terminated or truncated
    env.close()
    log = read_log(next((tmp_path / "logs").glob("*.mcap")))
    from gymfg_il.errors import ConfigError
    from gymfg_il.recording.replay import world_for

    with pytest.raises(ConfigError, match="pass the teams"):
        world_for(log)
    world = world_for(log, teams=[team()])
    assert replay_episode(log, log.complete_episodes[0], world=world).identical


def test_reset_options_and_the_reason_of_the_end_are_logged(tmp_path):
    from gymfg_il.envs import AircraftEnv
    from gymfg_il.sim.initial import InitialConditions

    env = Recorder(AircraftEnv("altitude", "c172p", episode_time_s=30), tmp_path)
    start = InitialConditions(altitude_ft=350, airspeed_kts=105, heading_deg=90)
    env.reset(seed=4, options={"initial_conditions": start, "target": 120.0})
    done = False
    while not done:  # nose down from 350 ft: a crash, not the time limit
        _, _, terminated, truncated, _ = env.step(np.array([0.0, 0.6, 0.0, 0.6]))
        done = terminated or truncated
    env.close()
    log = read_log(next((tmp_path / "logs").glob("*.mcap")))
    (ep,) = log.complete_episodes
    assert ep.end["outcome"] == "crashed"
    assert ep.start_of("ego")["target"] == pytest.approx(350 + 120.0, abs=1)
    assert replay_episode(log, ep).identical  # from the logged start and target
