"""The LeRobot env plugin: what LeRobot's evaluation loop asks of an env, and a success that
agrees with our eval's."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.rollout.agents import AgentSpec


@pytest.fixture(scope="module")
def plugin():
    import gymfg_il.lerobot_env as plugin

    return plugin


def test_the_config_registers_as_gymfg_with_our_features(plugin):
    from lerobot.envs.configs import EnvConfig

    cfg = EnvConfig.get_choice_class("gymfg")(task="roll", images=["front"], image_size=64)
    assert cfg.type == "gymfg" and cfg.gym_id == "gym_gymfg/roll"
    assert cfg.features["agent_pos"].shape == (13,)
    assert cfg.features["environment_state"].shape == (3,)
    assert cfg.features["pixels/front"].shape == (64, 64, 3)
    assert cfg.features_map["environment_state"] == "observation.environment_state"
    assert cfg.features_map["pixels/front"] == "observation.images.front"
    envs = cfg.create_envs(n_envs=1)
    vec = envs["gymfg"][0]
    try:
        obs, _ = vec.reset(seed=[3], options={"lerobot_new_rollout": True})
        assert obs["agent_pos"].shape == (1, 13) and obs["environment_state"].shape == (1, 3)
        assert obs["pixels"]["front"].shape == (1, 64, 64, 3)
        assert obs["pixels"]["front"].dtype == np.uint8
        assert vec.call("_max_episode_steps")[0] == 900
        assert isinstance(vec.call("task")[0], str) and "roll" in vec.call("task_description")[0]
    finally:
        vec.close()


def test_a_bad_task_is_a_clear_error(plugin):
    with pytest.raises(ConfigError, match=r"task='rol'.*roll"):
        plugin.GymFGEnv(task="rol")


def test_success_agrees_with_eval_and_render_is_rgb(plugin):
    env = gym.make("gym_gymfg/roll", episode_time_s=20.0).unwrapped
    pilot = AgentSpec.controller().make(env.env)
    obs, info = env.reset(seed=5, options={"lerobot_new_rollout": True})
    assert info["is_success"] is False
    np.testing.assert_array_equal(obs["environment_state"], obs["agent_pos"][10:13])
    pilot.reset(5)
    done, steps = False, 0
    while not done:
        obs, _, terminated, truncated, info = env.step(pilot.act(obs["agent_pos"]))
        done, steps = terminated or truncated, steps + 1
    assert steps == 200 and info["is_success"] is True  # the controller holds its bank
    frame = env.render()
    assert frame.shape == (128, 128, 3) and frame.dtype == np.uint8
    assert env.metadata["render_fps"] == 10
    # a flight that never reaches its target is no success
    env.reset(seed=5)
    for _ in range(200):
        obs, _, terminated, truncated, info = env.step(np.array([0.0, 0.0, 0.0, 0.0]))
        if terminated or truncated:
            break
    assert info["is_success"] is False
    env.close()


def test_the_config_is_the_flight_options_under_lerobots_names(plugin):
    from gymfg_il.envs import FlightSpec

    cfg = plugin.GymFGEnv(task="heading", fps=30, episode_time_s=20.0, turbulence="light")
    spec = FlightSpec.solo(task="heading", agent_hz=30, episode_time_s=20, turbulence="light")
    assert cfg.flight_options().flight() == spec
    env = cfg.make_one()
    try:
        assert env.flight == spec and env.metadata["render_fps"] == 30
    finally:
        env.close()
    with pytest.raises(ConfigError, match="turbulence='gusty'"):
        plugin.GymFGEnv(turbulence="gusty")
