"""The one rollout loop: what it records is what was flown, for one aircraft or many."""

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent, RandomAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs import AircraftEnv, FlightSpec, OfflineEnv
from gymfg_il.errors import ActionError, ConfigError, EnvStateError
from gymfg_il.rollout import AgentSpec, Rollout, fly_many
from gymfg_il.tasks import ReachStaticTargetAltitudeTask, ReachStaticTargetRollTask


class Wild:
    """Pushes every surface past its stop, so clipping shows."""

    def reset(self, seed=None):
        pass

    def act(self, observation, opponent_states=None):
        return np.array([3.0, -2.0, 0.5, 1.7])


def test_records_hold_what_the_env_flew_and_match_a_hand_loop(make_env):
    env = make_env("roll", episode_time_s=5)
    pilot = RandomAgent(scale=0.4)
    episode = Rollout(env, [pilot]).episode(7)
    t = episode.solo
    assert len(t) == 50 and t.observations.shape == (50, len(env.observation_names))
    assert np.array_equal(t.actions, t.labels)  # nobody else labels: the pilot's own action
    # by hand: the same seed and agent give the same observations, rewards and states
    obs, _ = env.reset(seed=7)
    pilot.reset(7)
    for k in range(50):
        assert np.array_equal(obs, t.observations[k])
        obs, reward, *_ = env.step(pilot.act(obs))
        assert reward == t.rewards[k] and np.array_equal(env.world.slots[0].state, t.states[k])
    assert np.array_equal(obs, t.final_observation)
    assert episode.truncated and episode.outcome == "time limit"


def test_actions_are_clipped_once_to_the_contract_and_labels_too(make_env):
    env = make_env("roll", episode_time_s=2)
    episode = Rollout(env, [Wild()], experts=[Wild()]).episode(0)
    for rows in (episode.actions, episode.solo.labels):
        assert np.array_equal(rows[0], [1.0, -1.0, 0.5, 1.0])


def test_noise_moves_what_is_flown_not_the_labels_and_repeats_by_seed(make_env):
    env = make_env("pitch", episode_time_s=3)
    expert = controller_for(env.task, "c172p", env.dt, 0.75)
    noisy = Rollout(env, [expert], noise=0.1).episode(4)
    t = noisy.solo
    # every control, the throttle too (a clone never saw the speed loop work without it)
    for axis in range(4):
        moved = t.actions[:, axis] - t.labels[:, axis]
        assert 0.05 < moved.std() < 0.15, (axis, moved.std())
    again = Rollout(env, [expert], noise=0.1).episode(4)
    assert np.array_equal(again.solo.actions, t.actions)


def test_a_nan_from_a_pilot_is_an_action_error(make_env):
    class Broken(Wild):
        def act(self, observation, opponent_states=None):
            return np.array([np.nan, 0, 0, 0.5])

    with pytest.raises(ActionError, match="aileron=nan"):
        Rollout(make_env(), [Broken()]).episode(0)


def test_a_team_rollout_records_every_aircraft_and_each_teams_view():
    red = Team(
        "red",
        [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in (1, 2)],
        episode_time_s=4,
    )  # fmt: skip
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetRollTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent((0.1, 0.0, 0.0, 0.8))])])
    with pytest.raises(ConfigError, match="team"):
        Rollout(env, [ConstantAgent()] * 2)
    rollout = Rollout(env, [ConstantAgent(), RandomAgent()], team=red)
    episode = rollout.episode(11)
    assert list(episode.trajectories) == ["red-1", "red-2", "blue-1"]
    assert all(len(t) == 40 for t in episode.trajectories.values())
    blue_actions = episode.trajectories["blue-1"].actions
    assert np.array_equal(blue_actions, np.tile([0.1, 0.0, 0.0, 0.8], (40, 1)))
    red_view, blue_view = episode.views["red"], episode.views["blue"]
    assert len(red_view) == 40 and red_view[0].callsigns == ["blue-1"]
    assert blue_view[-1].callsigns == ["red-1", "red-2"] and blue_view[-1].values.shape == (2, 6)
    # what blue saw of red-2 at the last step is red-2's position and orientation then
    last = episode.trajectories["red-2"].states[-1]
    assert np.array_equal(blue_view[-1].values[1], last[env.world.view_idx])
    with pytest.raises(EnvStateError, match="reset"):
        rollout.step()
    env.close()


def test_episodes_on_workers_are_the_episodes_of_one_process():
    flight = FlightSpec.solo("c172p", "heading", episode_time_s=4)
    one = fly_many(flight, AgentSpec.controller(), [3, 4], noise=0.05)
    two = fly_many(flight, AgentSpec.controller(), [3, 4], 2, noise=0.05)
    for a, b in zip(one, two, strict=True):
        assert np.array_equal(a.solo.states, b.solo.states)
        assert np.array_equal(a.solo.labels, b.solo.labels)
    env = AircraftEnv.from_flight(flight)
    hand = Rollout(env, [AgentSpec.controller().make(env)], noise=0.05).episode(3)
    assert np.array_equal(hand.solo.actions, one[0].solo.actions)
    env.close()


def test_when_a_team_crashes_the_others_are_cut_short_and_the_outcome_says_why():
    from gymfg_il.sim.initial import InitialConditions

    red = Team("red", [(c172p("red-1"), ReachStaticTargetAltitudeTask)], episode_time_s=60)
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetRollTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent((0.0, 0.0, 0.0, 0.8))])])
    low = {"initial_conditions": {"red-1": InitialConditions(altitude_ft=400, airspeed_kts=110)}}
    dive = ConstantAgent((0.0, 1.0, 0.0, 0.7))  # full nose down from 400 ft
    episode = Rollout(env, [dive], team=red).episode(3, options=low)
    red_t, blue_t = episode.trajectories["red-1"], episode.trajectories["blue-1"]
    assert red_t.terminated and red_t.reason == "crashed" and not red_t.truncated
    assert blue_t.truncated and not blue_t.terminated and len(blue_t) == len(red_t)
    assert episode.outcome == "crashed" and not episode.truncated
    assert (
        episode.options["initial_conditions"]["red-1"]["initial_conditions"]["altitude_ft"] == 400
    )
    # the last observation of each aircraft is the one its own last step led to
    assert not np.array_equal(red_t.final_observation, red_t.observations[-1])
    env.close()


def test_every_pilot_starts_from_the_trim_it_is_handed():
    """The controls a trimmed start begins with reach the person's stick, the assistant
    beside them, and the autopilots the env flies for its own opponents: none opens with a
    step away from the trim."""
    from gymfg_il.manual.controller import ManualController
    from gymfg_il.manual.takeover import Takeover

    env = AircraftEnv("altitude", "c172p")
    assist = controller_for(env.task, "c172p", env.dt)
    takeover = Takeover(ManualController("keyboard"), assist)
    rollout = Rollout(env, [takeover])
    rollout.reset(3)
    start = env.world.slots[0].action
    assert start[1] != 0.0  # the trim's elevator
    assert np.array_equal(takeover.human.values, start)
    assert assist.pitch_pid.bias == -start[1] and assist.throttle_trim == start[3]
    env.close()

    red = Team("red", [(c172p("red-1"), ReachStaticTargetAltitudeTask)])
    blue = Team("blue", [(c172p("blue-1"), ReachStaticTargetAltitudeTask)])
    opponent = controller_for(ReachStaticTargetAltitudeTask(), "c172p", 0.1)
    offline = OfflineEnv([(blue, [opponent])])
    offline.reset(red, seed=1)
    theirs = offline.world.by_callsign["blue-1"].action
    assert opponent.pitch_pid.bias == -theirs[1] and opponent.throttle_trim == theirs[3]


def test_an_opponent_view_beyond_the_pose_works_without_multiplayer():
    red = Team("red", [(c172p("red-1"), ReachStaticTargetAltitudeTask)])
    blue = Team("blue", [(c172p("blue-1"), ReachStaticTargetAltitudeTask)])
    env = OfflineEnv([(blue, [ConstantAgent()])], opponent_view=("altitude_ft", "airspeed_kts"))
    _, opponents = env.reset(red, seed=0)
    assert opponents.shape == (1, 2) and opponents[0, 1] > 50.0
