"""The controllers reach and hold their targets on each of the paper's aircraft."""

import numpy as np
import pytest

from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.controllers.pid import PID
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError

CASES = [
    ("altitude", 1000, 50),
    ("altitude", -1000, 50),
    ("roll", 30, 2),
    ("roll", -30, 2),
    ("heading", 90, 3),
    ("airspeed", 15, 3),
    ("airspeed", -15, 3),
]


def fly(family, model, target, seconds=150, dynamic=False):
    kwargs = {"target": target} if target is not None else {}
    env = AircraftEnv(family, model, dynamic=dynamic, task_kwargs=kwargs, episode_time_s=seconds)
    pilot = controller_for(
        env.task, env.aircraft.model, env.dt, env.aircraft.profile.cruise_throttle
    )
    obs, _ = env.reset(seed=0)
    pilot.reset(0)
    errors, actions, done = [], [], False
    while not done:
        action = pilot.act(obs)
        obs, _, terminated, truncated, _ = env.step(action)
        errors.append(obs[-2])  # the target's error
        actions.append(action)
        done = terminated or truncated
    env.close()
    assert not terminated
    # no chatter: the surfaces move smoothly from step to step
    assert np.abs(np.diff(np.array(actions)[:, :3], axis=0)).mean() < 0.01
    return np.abs(np.array(errors))


@pytest.mark.parametrize("model", ["c172p", "f15", "A320"])
@pytest.mark.parametrize(("family", "target", "tolerance"), CASES)
def test_controller_reaches_and_holds(model, family, target, tolerance):
    errors = fly(family, model, target)
    assert errors[0] > 10 * tolerance or family == "airspeed"  # a real manoeuvre
    assert errors[-400:].max() < tolerance  # held for the last 40 s


@pytest.mark.parametrize("model", ["c172p", "f15", "A320"])
@pytest.mark.parametrize(("family", "bound"), [("altitude", 60), ("roll", 8), ("heading", 10)])
def test_dynamic_targets_are_tracked_with_bounded_error(model, family, bound):
    errors = fly(family, model, None, seconds=90, dynamic=True)
    assert errors[300:].max() < bound


def test_pid_anti_windup_and_derivative_on_measurement():
    pid = PID(1.0, 1.0, 0.5, out_min=-1, out_max=1)
    for _ in range(100):
        out = pid(10.0, 0.0, 0.1)
    assert out == 1.0 and pid.integral < 5  # saturated, integral did not wind up
    pid.reset()
    first = pid(0.0, 0.0, 0.1)
    jumped = pid(5.0, 0.0, 0.1)  # setpoint jump: no derivative kick
    assert first == 0.0 and jumped == pytest.approx(1.0)
    with pytest.raises(ConfigError):
        pid(0, 0, 0.0)
    with pytest.raises(ConfigError):
        PID(1.0, out_min=1, out_max=0)


@pytest.mark.parametrize(("task", "target", "axis"), [("roll", 20, 0), ("sideslip", 4, 2)])
def test_labels_from_the_observed_integral_depend_on_the_observation_alone(task, target, axis):
    """Under DAgger the expert's roll (or slip) loop reads its integral from the
    observation: two experts that tracked different actions label the same observation
    alike; a plain track (a human's takeover) keeps the hand-back bumpless instead."""
    env = AircraftEnv(task, "c172p", task_kwargs={"target": target})
    obs, _ = env.reset(seed=0)
    nxt, *_ = env.step(np.array([0.1, 0.0, 0.0, 0.7]))
    env.close()
    summed = {"roll": "roll_deg_error_integral", "sideslip": "beta_deg_error_integral"}[task]
    loop = {"roll": "roll", "sideslip": "slip"}[task]
    labels, bumpless = [], []
    for applied in (-0.4, 0.4):
        for from_observation, out in ((True, labels), (False, bumpless)):
            pilot = controller_for(env.task, "c172p", env.dt, 0.7)
            names = list(env.task.observation_names)
            assert pilot.observed_integrals == {loop: names.index(summed)}
            pilot.reset(0)
            pilot.act(obs)
            action = np.array([0.0, 0.0, 0.0, 0.7])
            action[axis] = applied
            pilot.track(action, from_observation=from_observation)
            out.append(pilot.act(nxt)[axis])
    assert labels[0] == pytest.approx(labels[1], abs=1e-9)
    assert bumpless[1] - bumpless[0] == pytest.approx(0.8, abs=1e-6)


def test_dagger_labels_keep_the_speed_loop_its_own_integral():
    """The approach's airspeed integral goes on summing while the throttle sits at idle,
    where the speed loop's anti-windup stops: labelling as ``collect dagger`` does, the
    labeller's throttle follows the pilot's (a second autopilot, DART-noised) instead of a
    wound-up sum that held it at idle through the whole approach."""
    env = AircraftEnv("approach", "c172p")
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=3)
    pilot = controller_for(env.task, "c172p", env.dt, env.aircraft.profile.cruise_throttle)
    labeller = controller_for(env.task, "c172p", env.dt, env.aircraft.profile.cruise_throttle)
    pilot.reset(3)
    labeller.reset(3)
    gaps, wound = [], []
    summed = list(env.task.observation_names).index("airspeed_kts_error_integral")
    for step in range(1200):
        clean = np.clip(pilot.act(obs), [-1, -1, -1, 0], 1)
        label = np.clip(labeller.act(obs), [-1, -1, -1, 0], 1)
        flown = np.clip(clean + rng.normal(0.0, 0.05, 4), [-1, -1, -1, 0], 1)
        labeller.track(flown, from_observation=True)
        if step >= 300:
            gaps.append(abs(label[3] - clean[3]))
            wound.append(abs(obs[summed]) > 1.5 * abs(labeller.speed_pid.integral) + 50)
        obs, *_ = env.step(flown)
    env.close()
    assert np.mean(wound) > 0.5  # the task's sum and the loop's integral did part
    assert np.median(gaps) < 0.1


@pytest.mark.parametrize("model", ["c172p", "f15", "A320"])
@pytest.mark.parametrize("target", [4.0, -4.0])
def test_the_rudder_holds_a_sideslip_target(model, target):
    errors = fly("sideslip", model, target, seconds=60)
    assert errors[0] > 3.5  # from coordinated flight into a slip
    assert errors[-400:].max() < 0.5  # held for the last 40 s, wings level


def test_the_rudder_task_is_found_by_the_papers_name_and_its_dynamic_one_is_tracked():
    from gymfg_il.tasks import ReachStaticTargetSideslipTask, task_class

    assert task_class("rudder") is ReachStaticTargetSideslipTask
    errors = fly("sideslip", "c172p", None, seconds=60, dynamic=True)
    assert errors[100:].max() < 1.0


def test_each_task_declares_its_expert_and_the_controller_is_built_from_it():
    """#53: no table of experts in controllers/; a task of your own declares one too."""
    from gymfg_il.tasks import DummyTask, Task, task_class
    from gymfg_il.tasks.experts import Expert, Targets

    class Climb(DummyTask):
        def expert(self):
            return Expert(Targets(vertical="climb", vertical_source=5.0))

    assert controller_for(Climb(), "c172p", 0.1).targets.vertical_source == 5.0
    roll = task_class("roll")().expert()
    assert roll == Expert(Targets(lateral="roll", lateral_source="roll_deg_target"))
    assert task_class("airspeed")().expert().targets == Targets(speed_source="airspeed_kts_target")
    with pytest.raises(ConfigError, match=r"no controller for Task: declare its expert"):
        controller_for(Task(), "c172p", 0.1)


def test_maneuvers_bank_as_the_profile_says_and_close_lines_in_the_same_seconds():
    from gymfg_il.controllers.gains import GAINS, MANEUVER_GAINS
    from gymfg_il.tasks.approach import ApproachTask

    def pilot(task, model):
        env = AircraftEnv(task, model)
        built = controller_for(env.task, model, env.dt)
        env.close()
        return built

    c172 = pilot("approach", "c172p")  # the c172p flies its maneuvers as before the scaling
    assert c172.targets == ApproachTask.expert_targets and c172.gains == GAINS["c172p"]
    jet = pilot("approach", "f15")
    assert jet.gains.max_roll_deg == 45.0 and jet.gains.roll == MANEUVER_GAINS["f15"].roll
    assert jet.targets.track_gain == pytest.approx(0.03 / 3.0)  # approaching 3x as fast
    assert pilot("formation", "A320").targets.track_gain == pytest.approx(0.2 * 110.0 / 280.0)
    assert pilot("heading", "f15").gains == GAINS["f15"]  # target tasks keep the model's set
