import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import gymfg_il  # noqa: F401  (registers the ids)
from gymfg_il.envs.registration import IDS
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions


@pytest.mark.parametrize("env_id", sorted(IDS))
def test_check_env_passes_for_every_registered_id(env_id):
    env = gym.make(env_id, disable_env_checker=True, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (128, 128, 3) and frame.dtype == np.uint8
    assert env.metadata["render_fps"] == 10
    env.close()


def test_make_kwargs_select_aircraft_dynamic_and_ranges():
    env = gym.make(
        "GymFG/Roll-v0",
        aircraft="f15",
        dynamic=True,
        task_kwargs={"target_range": (10, 10)},
        agent_hz=20,
    )
    _obs, info = env.reset(seed=0)
    assert env.unwrapped.aircraft.model == "f15"
    assert env.unwrapped.dt == 0.05
    assert info["target"] == pytest.approx(0, abs=1e-9)  # starts at the start roll...
    assert env.unwrapped.task.target_value(1799) == 10  # ...and moves to the drawn waypoints
    assert type(env.unwrapped.task).__name__ == "ReachDynamicTargetRollTask"


def trajectory(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    rewards = []
    for a in actions:
        obs, r, *_ = env.step(a)
        out.append(obs)
        rewards.append(r)
    return np.array(out), np.array(rewards)


def test_same_seed_and_actions_are_bit_identical(make_env):
    actions = np.random.default_rng(0).uniform(
        [-0.3, -0.3, -0.3, 0.5], [0.3, 0.3, 0.3, 1.0], (200, 4)
    )
    env = make_env("heading", "c172p", dynamic=True)
    a = trajectory(env, 5, actions)
    trajectory(env, 6, actions[::-1])
    b = trajectory(env, 5, actions)
    c = trajectory(make_env("heading", "c172p", dynamic=True), 5, actions)
    for other in (b, c):
        assert np.array_equal(a[0], other[0]) and np.array_equal(a[1], other[1])
    d = trajectory(env, 7, actions)
    assert not np.array_equal(a[0], d[0])


def test_reset_options(make_env):
    env = make_env("altitude")
    _, info = env.reset(
        seed=0, options={"target": 300, "initial_conditions": InitialConditions(altitude_ft=6000)}
    )
    assert info["target"] == pytest.approx(6000 + 300, abs=1)
    with pytest.raises(ConfigError, match="unknown reset options"):
        env.reset(options={"targte": 1})


def test_time_limit_is_in_seconds(make_env):
    env = make_env("dummy", agent_hz=30, episode_time_s=2)
    env.reset(seed=0)
    steps, truncated = 0, False
    while not truncated:
        *_, truncated, _ = env.step(np.array([0, 0, 0, 0.7], np.float32))
        steps += 1
    assert steps == 60


def test_bad_env_arguments():
    from gymfg_il.envs.single import AircraftEnv
    from gymfg_il.errors import RateError, UnknownAircraftError

    with pytest.raises(RateError):
        AircraftEnv("altitude", agent_hz=7)
    with pytest.raises(UnknownAircraftError):
        AircraftEnv("altitude", aircraft="cessna")
    with pytest.raises(ConfigError, match="render_mode"):
        AircraftEnv(render_mode="ansi")


def test_human_render_mode_shows_the_camera_in_a_window():
    from gymfg_il.envs.single import AircraftEnv

    env = AircraftEnv("roll", render_mode="human", agent_hz=30, render_size=(64, 48))
    assert env.render() is None  # human mode shows, returns nothing
    env.reset(seed=0)
    for _ in range(3):
        env.step(np.array([0.3, 0.0, 0.0, 0.7], np.float32))
    window = env._window
    assert window is not None and window.fps == 30 and window.screen.get_size() == (512, 512)
    shown = window.pg.surfarray.array3d(window.screen)
    assert shown[:, :100, 2].mean() > shown[:, :100, 1].mean()  # sky on top
    frame = env.camera_frame("chase", 32)
    assert frame.shape == (32, 32, 3)
    env.close()
    assert env._window is None
