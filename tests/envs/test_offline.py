import functools

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent, RandomAgent
from gymfg_il.aircraft import a320, c172p, f15
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs import OfflineEnv
from gymfg_il.envs.scenarios import formation, head_on_merge
from gymfg_il.errors import ActionError, ConfigError, EnvStateError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks import DummyTask, LevelFlightTask, ReachStaticTargetAltitudeTask, geometry


def paper_loop(env, team, agents, seed=0):
    team_state, opponent_states = env.reset(team, seed=seed)
    for agent in agents:
        agent.reset(seed)
    done, steps, rewards = False, 0, []
    while not done:
        team_actions = [
            agent.act(s, opponent_states) for s, agent in zip(team_state, agents, strict=True)
        ]
        team_state, opponent_states, r, terminated, truncated, info = env.step(
            np.hstack(team_actions)
        )
        rewards.append(r)
        done = terminated or truncated
        steps += 1
    return steps, terminated, truncated, info, np.array(rewards)


def level_pilots(env, team):
    pilots = []
    for slot in env.world.team_slots[team.name]:
        pilots.append(
            controller_for(
                slot.task, slot.aircraft.model, env.dt, slot.aircraft.profile.cruise_throttle
            )
        )
    return pilots


def test_paper_loop_runs_a_90_s_episode_with_the_three_paper_aircraft():
    team = Team(
        "red",
        [
            (f15("red-one"), LevelFlightTask),
            (c172p("red-two"), LevelFlightTask),
            (a320("red-three"), LevelFlightTask),
        ],
    )
    blue = Team("blue", [(c172p("blue-one"), DummyTask)])
    env = OfflineEnv([(blue, [ConstantAgent()])])
    env.reset(team, seed=0)
    steps, terminated, truncated, info, rewards = paper_loop(env, team, level_pilots(env, team))
    assert steps == 900 and truncated and not terminated
    assert info["time_s"] == pytest.approx(90.0)
    assert rewards.shape == (900, 3)
    assert info["reasons"] == {} or set(info["reasons"]) == {"blue-one"}
    # all three flew level under their controllers: high reward at the end
    assert rewards[-100:].mean(axis=0).min() > 0.8


def test_opponents_see_only_position_and_orientation():
    red = Team("red", [(f15("red-one"), DummyTask)])
    blue = Team("blue", [(c172p("blue-one"), DummyTask), (c172p("blue-two"), DummyTask)])
    env = OfflineEnv([(blue, [ConstantAgent(), ConstantAgent()])])
    _, opp = env.reset(red, seed=1)
    assert opp.shape == (2, 6)
    blue_state = env.world.by_callsign["blue-one"].state
    idx = [0, 1, 2, 4, 5, 6]  # lat, lon, alt, roll, pitch, heading in the catalogue
    assert np.array_equal(opp[0], blue_state[idx])
    env2 = OfflineEnv([(blue, [ConstantAgent(), ConstantAgent()])], opponent_view=("altitude_ft",))
    _, opp2 = env2.reset(red, seed=1)
    assert opp2.shape == (2, 1)


def test_reward_targets_see_teammates_fully_and_opponents_restricted():
    seen = {}

    def spy(ctx):
        seen.update({k: v.names() for k, v in ctx.targets.items()})
        return 0.0

    spying = functools.partial(DummyTask, reward=spy)
    red = Team(
        "red",
        [(f15("red-one"), spying), (f15("red-two"), DummyTask)],
        reward_function_targets={f15("red-one"): [f15("red-two"), c172p("blue-one")]},
    )
    blue = Team("blue", [(c172p("blue-one"), DummyTask)])
    env = OfflineEnv([(blue, [ConstantAgent()])])
    env.reset(red, seed=0)
    env.step(np.hstack([[0, 0, 0, 0.8], [0, 0, 0, 0.8]]))
    assert "airspeed_kts" in seen["red-two"]
    assert seen["blue-one"] == (
        "lat_deg",
        "lon_deg",
        "altitude_ft",
        "roll_deg",
        "pitch_deg",
        "heading_deg",
    )


def test_reward_target_outside_the_simulation_is_refused():
    red = Team(
        "red",
        [(f15("red-one"), DummyTask)],
        reward_function_targets={f15("red-one"): [f15("ghost")]},
    )
    with pytest.raises(ConfigError, match="ghost"):
        OfflineEnv().reset(red)


def test_history_window_reaches_the_reward():
    lengths = []
    task = functools.partial(
        DummyTask, history_window=5, reward=lambda ctx: lengths.append(len(ctx.history)) or 0.0
    )
    red = Team("red", [(c172p("one"), task)])
    env = OfflineEnv()
    env.reset(red, seed=0)
    for _ in range(8):
        env.step([0, 0, 0, 0.7])
    assert lengths == [1, 2, 3, 4, 5, 5, 5, 5]


def test_crashing_aircraft_terminates_cleanly_and_others_fly_on():
    low = InitialConditions(altitude_ft=400, airspeed_kts=110)
    red = Team("red", [(c172p("diver"), DummyTask), (c172p("flyer"), DummyTask)])
    env = OfflineEnv()
    env.reset(red, seed=0, options={"initial_conditions": {"diver": low}})
    terminated = False
    for _ in range(300):
        _, _, rewards, terminated, _truncated, info = env.step(
            np.hstack([[0, 1.0, 0, 0.0], [0, 0, 0, 0.8]])
        )
        if info["terminated"][0]:
            break
    assert info["reasons"] == {"diver": "crashed"}
    assert info["terminated"] == [True, False] and not terminated
    frozen = env.world.by_callsign["diver"].state.copy()
    _, _, rewards, *_ = env.step(np.hstack([[0, 0, 0, 0.7], [0, 0, 0, 0.8]]))
    assert rewards[0] == 0.0
    assert np.array_equal(env.world.by_callsign["diver"].state, frozen)


def test_same_seed_and_actions_give_identical_trajectories():
    red = Team("red", [(f15("one"), DummyTask)])
    blue = Team("blue", [(c172p("two"), DummyTask)])

    def run(env):
        _, _, rewards, *_ = paper_loop(env, red, [RandomAgent()], seed=11)
        return rewards, env.world.by_callsign["two"].state.copy()

    env = OfflineEnv([(blue, [RandomAgent()])])
    first = run(env)
    run_other = paper_loop(env, red, [RandomAgent()], seed=12)
    again = run(env)
    fresh = run(OfflineEnv([(blue, [RandomAgent()])]))
    assert run_other is not None
    for other in (again, fresh):
        assert np.array_equal(first[0], other[0]) and np.array_equal(first[1], other[1])


@pytest.mark.parametrize(
    "action, match",
    [
        ([0, 0, 0], "shape"),
        ([[0, 0, 0, 0.5]] * 2, "shape"),
        ([0, float("nan"), 0, 0.5], "elevator=nan"),
        ([0, 0, float("inf"), 0.5], "rudder=inf"),
        (["a", 0, 0, 0], "not an array of numbers"),
    ],
)
def test_bad_actions_never_reach_jsbsim(action, match):
    red = Team("red", [(c172p("one"), DummyTask)])
    env = OfflineEnv()
    env.reset(red, seed=0)
    before = env.world.by_callsign["one"].sim.fdm["simulation/sim-time-sec"]
    with pytest.raises(ActionError, match=match):
        env.step(action)
    assert env.world.by_callsign["one"].sim.fdm["simulation/sim-time-sec"] == before


def test_out_of_range_actions_are_clipped():
    red = Team("red", [(c172p("one"), DummyTask)])
    env = OfflineEnv()
    env.reset(red, seed=0)
    env.step([5, -5, 2, 3])
    assert env.world.by_callsign["one"].action.tolist() == [1, -1, 1, 1]


def test_step_before_reset_and_after_the_end():
    env = OfflineEnv()
    with pytest.raises(EnvStateError):
        env.step([0, 0, 0, 0.5])
    with pytest.raises(EnvStateError, match="team"):
        env.reset()
    red = Team("red", [(c172p("one"), DummyTask)], episode_time_s=0.2)
    env.reset(red, seed=0)
    env.step([0, 0, 0, 0.5])
    *_, truncated, _ = env.step([0, 0, 0, 0.5])
    assert truncated
    with pytest.raises(EnvStateError):
        env.step([0, 0, 0, 0.5])


def test_smallest_episode_time_throttles_all_teams():
    red = Team("red", [(c172p("one"), DummyTask)], episode_time_s=90)
    blue = Team("blue", [(c172p("two"), DummyTask)], episode_time_s=3)
    env = OfflineEnv([(blue, [ConstantAgent()])])
    steps, _, truncated, *_ = paper_loop(env, red, [ConstantAgent()])
    assert steps == 30 and truncated


def test_formation_scenario_places_aircraft_jointly():
    red = Team(
        "red", [(c172p("lead"), DummyTask), (c172p("wing"), DummyTask), (c172p("slot"), DummyTask)]
    )
    env = OfflineEnv(scenario=formation(spacing_ft=300, jitter_ft=20))
    env.reset(red, seed=4)
    views = [env.world.by_callsign[c] for c in ("lead", "wing", "slot")]
    from gymfg_il.sim.properties import StateView

    lead, wing, slot = (StateView(v.state) for v in views)
    assert geometry.distance_ft(lead, wing) == pytest.approx(300 * 2**0.5, abs=60)
    assert geometry.distance_ft(lead, slot) == pytest.approx(600 * 2**0.5, abs=60)
    from gymfg_il.tasks.orientation import angle_difference_deg

    assert angle_difference_deg(wing.heading_deg, lead.heading_deg) == pytest.approx(0, abs=1e-3)
    env.reset(seed=4)
    assert geometry.distance_ft(
        StateView(views[0].state), StateView(views[1].state)
    ) == pytest.approx(geometry.distance_ft(lead, wing), abs=1e-6)


def test_head_on_merge_points_teams_at_each_other():
    red = Team("red", [(f15("red-one"), DummyTask)])
    blue = Team("blue", [(f15("blue-one"), DummyTask)])
    env = OfflineEnv([(blue, [ConstantAgent()])], scenario=head_on_merge(distance_ft=20000))
    env.reset(red, seed=0)
    from gymfg_il.sim.properties import StateView
    from gymfg_il.tasks.orientation import angle_difference_deg

    r = StateView(env.world.by_callsign["red-one"].state)
    b = StateView(env.world.by_callsign["blue-one"].state)
    assert geometry.distance_ft(r, b) == pytest.approx(20000, rel=0.01)
    assert angle_difference_deg(geometry.bearing_deg(r, b), r.heading_deg) == pytest.approx(
        0, abs=0.5
    )
    assert angle_difference_deg(geometry.bearing_deg(b, r), b.heading_deg) == pytest.approx(
        0, abs=0.5
    )


def test_an_opponent_flown_by_a_recurrent_policy_carries_its_state_and_starts_afresh(
    tiny_gru, carried_state
):
    from gymfg_il.policies.agent import PolicyAgent
    from gymfg_il.rollout import Rollout

    red = Team("red", [(c172p("red-1"), ReachStaticTargetAltitudeTask)], episode_time_s=5)
    blue = Team("blue", [(c172p("blue-1"), ReachStaticTargetAltitudeTask)], episode_time_s=5)
    gru = PolicyAgent.load(tiny_gru)
    env = OfflineEnv([(blue, [gru])])
    rollout = Rollout(env, [ConstantAgent()], team=red)
    for seed in (0, 1):  # the env resets its agents at every episode's start
        flown = rollout.episode(seed).trajectories["blue-1"]
        assert len(flown) == 50
        carried_state(gru.policy, flown.observations, flown.actions)
    env.close()
