import functools
import math

import numpy as np
import pytest

import gymfg_il.tasks as tasks
from gymfg_il.aircraft import c172p
from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import INDEX, NAMES, StateView
from gymfg_il.tasks import geometry, orientation, rewards
from gymfg_il.tasks.library import TASK_FAMILIES, task_class


def bound(task, steps=900):
    task.bind(c172p("x"), 0.1, steps)
    return task


def state(**values):
    s = np.zeros(len(NAMES))
    s[INDEX["altitude_agl_ft"]] = 5000
    s[INDEX["airspeed_kts"]] = 100
    for k, v in values.items():
        s[INDEX[k]] = v
    return s


@pytest.mark.parametrize(
    "cls", sorted({c for pair in TASK_FAMILIES.values() for c in pair}, key=lambda c: c.__name__)
)
def test_every_task_docstring_is_its_spec(cls):
    doc = cls.__doc__ or ""
    for part in ("Observation", "Reward", "Start and end"):
        assert part in doc, f"{cls.__name__} docstring lacks {part}"


def test_static_target_is_fixed_and_relative_to_start():
    task = bound(tasks.ReachStaticTargetAltitudeTask(target=500))
    task.reset(state(altitude_ft=4000), np.random.default_rng(0))
    assert task.target_value(0) == task.target_value(899) == 4500
    obs = task.observe(state(altitude_ft=4100), 10)
    assert obs[-3] == 4500 and obs[-2] == 400
    assert len(obs) == len(task.observation_names)


def test_error_integral_sums_each_step_once_and_restarts_with_the_episode():
    task = bound(tasks.ReachStaticTargetRollTask(target=10))
    assert task.observation_names[-1] == "roll_deg_error_integral"
    for _ in range(2):
        task.reset(state(roll_deg=0), np.random.default_rng(0))
        integrals = []
        for step, roll in enumerate([0.0, 4.0, 8.0, 12.0]):
            task.observe(state(roll_deg=roll), step)  # observed twice: counted once
            integrals.append(task.observe(state(roll_deg=roll), step)[-1])
        # errors 10, 6, 2, -2 deg, dt 0.1 s
        assert integrals == pytest.approx([1.0, 1.6, 1.8, 1.6])


def test_dynamic_target_moves_at_its_rate_and_is_seeded():
    a = bound(tasks.ReachDynamicTargetRollTask(hold_s=10))
    b = bound(tasks.ReachDynamicTargetRollTask(hold_s=10))
    a.reset(state(), np.random.default_rng(7))
    b.reset(state(), np.random.default_rng(7))
    ta = np.array([a.target_value(i) for i in range(900)])
    tb = np.array([b.target_value(i) for i in range(900)])
    assert np.array_equal(ta, tb)
    assert len(np.unique(np.round(ta, 6))) > 10  # it moves
    assert np.abs(np.diff(ta)).max() <= 5.0 * 0.1 + 1e-9  # at most 5 deg/s
    assert ta.min() >= -30 and ta.max() <= 30


def test_heading_error_wraps_across_north():
    task = bound(tasks.ReachStaticTargetHeadingTask(target=20))
    task.reset(state(heading_deg=350), np.random.default_rng(0))
    assert task.target_value(0) == pytest.approx(10)
    assert task.error(355, 0) == pytest.approx(15)
    obs = task.observe(state(heading_deg=5), 0)
    assert obs[-2] == pytest.approx(5)


def test_reward_is_one_lambda_over_states_and_targets():
    ctx = rewards.RewardContext(
        state=StateView(state(altitude_ft=5000)),
        prev_state=StateView(state(altitude_ft=4990)),
        action=np.array([0, 0, 0, 0.7]),
        prev_action=np.array([0, 0, 0, 0.7]),
        targets={
            "red-two": StateView(
                np.array([0.0, 0.0, 5200.0]), ("lat_deg", "lon_deg", "altitude_ft")
            )
        },
    )
    task = tasks.DummyTask(
        reward=lambda c: (
            -geometry.altitude_difference_ft(c.state, c.targets["red-two"])
            + (c.state.altitude_ft - c.prev_state.altitude_ft)
        )
    )
    assert task.reward(ctx) == pytest.approx(-200 + 10)
    assert tasks.DummyTask().reward(ctx) == 0.0


def test_target_reward_peaks_at_the_target():
    task = bound(tasks.ReachStaticTargetRollTask(target=30))
    task.reset(state(), np.random.default_rng(0))
    a = np.array([0, 0, 0, 0.7])

    def r(roll):
        return task.reward(
            rewards.RewardContext(StateView(state(roll_deg=roll)), StateView(state()), a, a)
        )

    assert r(30) == pytest.approx(1.0)
    assert r(25) == pytest.approx(math.exp(-1))
    assert r(0) < r(20) < r(29)


def test_envelope_termination():
    task = bound(tasks.DummyTask())
    assert task.termination(state()) is None
    assert task.termination(state(altitude_agl_ft=10)) == "crashed"
    assert task.termination(state(airspeed_kts=20)) == "stalled"
    assert task.termination(state(altitude_ft=99999)) == "above_ceiling"
    assert task.termination(state(airspeed_kts=float("nan"))) == "diverged"
    # JSBSim blown up by a ground strike between two steps: finite, but no flight
    assert task.termination(state(p_rad_s=-3.3e17, load_factor_g=-1.25e35)) == "diverged"
    assert task.termination(state(load_factor_g=45.0)) == "diverged"
    assert task.termination(state(q_rad_s=float("inf"))) == "diverged"
    assert task.termination(state(p_rad_s=4.0, load_factor_g=9.0)) is None  # an F-15 can


def _blow_up(sim):
    """Make ``sim`` return what JSBSim gave after an A320 struck the ground between two
    steps: rates of 3e17 rad/s, loads of 1e35 g, then NaN."""
    read = sim.read

    def blown_up():
        values = read()
        values[INDEX["p_rad_s"]], values[INDEX["load_factor_g"]] = -3.3e17, -1.25e35
        values[INDEX["altitude_agl_ft"]] = values[INDEX["heading_deg"]] = float("nan")
        return values

    sim.read = blown_up


def test_a_diverged_simulation_ends_the_episode_instead_of_failing_it():
    """An aircraft whose JSBSim state went NaN is terminated as diverged, with reward 0, at
    its last flown state (no NaN in what is observed or recorded), and the next episode
    flies: eval and collection go on."""
    from gymfg_il.envs.single import AircraftEnv

    env = AircraftEnv("heading", "A320", episode_time_s=5)
    env.reset(seed=0)
    slot = env.world.slots[0]
    env.step(np.array([0.0, 0.0, 0.0, 0.5]))
    last = slot.state.copy()
    _blow_up(slot.sim)
    obs, reward, terminated, truncated, _ = env.step(np.array([0.0, 0.0, 0.0, 0.5]))
    assert terminated and not truncated and reward == 0.0
    assert slot.reason == "diverged"
    assert np.array_equal(slot.state, last) and np.isfinite(obs).all()
    del slot.sim.read  # the instance's own read again
    obs, _ = env.reset(seed=1)
    assert not slot.blown and np.isfinite(obs).all()
    assert not env.step(np.array([0.0, 0.0, 0.0, 0.5]))[2]


def test_a_diverged_opponent_is_never_shown_as_nan():
    """Another team's aircraft that diverges is seen (opponent rows, reward targets) at its
    last flown state as it ends, then absent, so a reward aimed at it stays finite."""
    from gymfg_il import Team
    from gymfg_il.agent import ConstantAgent
    from gymfg_il.aircraft import f15
    from gymfg_il.envs import OfflineEnv
    from gymfg_il.tasks import DummyTask

    def chase(ctx):
        blue = ctx.targets.get("blue-1")
        return 0.0 if blue is None else -geometry.distance_ft(ctx.state, blue) / 1000

    red = Team(
        "red",
        [(c172p("red-1"), DummyTask(reward=chase))],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=10,
    )
    blue = Team("blue", [(f15("blue-1"), DummyTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent((0.0, 0.0, 0.0, 0.7))])])
    env.reset(red, seed=2)
    act = np.array([0.0, 0.0, 0.0, 0.7])
    _, before, *_ = env.step(act)
    _blow_up(env.world.by_callsign["blue-1"].sim)
    _, rows, reward, terminated, _, info = env.step(act)  # red scores before blue
    assert info["reasons"] == {"blue-1": "diverged"} and not terminated
    assert np.isfinite(rows).all() and np.array_equal(rows, before)
    assert math.isfinite(reward[0]) and reward[0] < 0  # aimed at blue's last flown position
    _, rows, reward, *_ = env.step(act)
    assert rows.shape == (0, 6) and reward[0] == 0.0  # gone, as a crashed aircraft is


def test_geometry_and_orientation():
    a = StateView(state(lat_deg=37.0, lon_deg=-122.0, altitude_ft=5000))
    north = StateView(state(lat_deg=37.01, lon_deg=-122.0, altitude_ft=5000))
    east = StateView(state(lat_deg=37.0, lon_deg=-121.99, altitude_ft=6000))
    assert geometry.distance_ft(a, north) == pytest.approx(3643, rel=0.01)  # 0.01 deg ~ 1.11 km
    assert geometry.bearing_deg(a, north) == pytest.approx(0, abs=0.1)
    assert geometry.bearing_deg(a, east) == pytest.approx(90, abs=0.1)
    assert geometry.altitude_difference_ft(a, east) == 1000
    assert orientation.angle_difference_deg(10, 350) == 20
    assert orientation.wrap_180(270) == -90
    assert orientation.bank_for_turn_rate(3, 110) == pytest.approx(16.9, abs=0.3)


@pytest.mark.parametrize(
    "bad",
    [
        {"target_range": (5, -5)},
        {"target": float("inf")},
        {"hold_s": 0},
        {"reward_scale": -1},
        {"history_window": -1},
        {"reward": 3},
    ],
)
def test_bad_task_arguments(bad):
    with pytest.raises(ConfigError):
        tasks.ReachDynamicTargetAltitudeTask(**bad)


def test_task_lookup_by_name():
    assert task_class("roll", dynamic=True) is tasks.ReachDynamicTargetRollTask
    with pytest.raises(ConfigError, match="altitude"):
        task_class("altitud")
    with pytest.raises(ConfigError, match="dynamic"):
        task_class("level", dynamic=True)
    assert isinstance(functools.partial(tasks.ReachStaticTargetRollTask, target=3)(), tasks.Task)


def test_a_task_path_to_something_else_names_its_type_not_its_value():
    """#52.12: ``sys:modules`` as a task printed all of ``sys.modules`` in the error."""
    with pytest.raises(ConfigError) as err:
        task_class("sys:modules")
    assert str(err.value).startswith("'sys:modules' is a dict, not a Task class")
    assert len(str(err.value)) < 200
