"""The env processes' numpy pass (``rl.forward``) samples what the torch policy would: the same
mean, value and log-probability, and noise of the policy's own spread."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest
import torch

pytest.importorskip("stable_baselines3")

from stable_baselines3.common.vec_env import DummyVecEnv

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.modeling_mlp import MLPPolicy
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.envs import make_env
from gymfg_il.rl.grouped.forward import NumpyActorCritic
from gymfg_il.rl.grouped.sampling import sampling_copy
from gymfg_il.rl.model import make_model


def _policy(tmp_path, memory="none"):
    """A policy some updates away from its start and observations about its statistics; with
    ``memory``, the policy remembers its task's loops (``MLPPolicy.integral``)."""
    flight = FlightSpec.solo("c172p", "altitude", episode_time_s=3.0)
    names = list(flight.make_env().task.observation_names)
    config = MLPConfig(hidden=[32, 16])
    if memory != "none":
        config = MLPConfig(
            hidden=[32, 16], memory=memory, memory_flight=flight.to_dict(), memory_observation=names
        )
    n_obs = len(names) + len(config.memory_names)
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    stats = [{"mean": rng.normal(size=n), "std": rng.uniform(0.5, 2, size=n)} for n in (n_obs, 4)]
    module = MLPPolicy(config, *stats)
    fn = partial(make_env, flight.to_dict(), [0.0] * 4, [0.3] * 4, 0.0, module.memory_maker())
    cfg = PPORunConfig(task="altitude", aircraft="c172p")
    model = make_model(cfg, DummyVecEnv([fn]), module, tmp_path, "cpu", flight.agent_hz)
    policy = model.policy
    with torch.no_grad():  # a policy some updates away from its start, critic included
        for p in policy.parameters():
            p.add_(0.1 * torch.randn_like(p))
    obs_mean, obs_std = stats[0]["mean"], stats[0]["std"]
    obs = (obs_mean + obs_std * rng.normal(size=(64, n_obs))).astype(np.float32)
    model.env.close()
    return policy, obs


@pytest.mark.parametrize("memory", ["none", "vertical"])
def test_the_numpy_pass_samples_as_the_policy_does(tmp_path, memory):
    policy, obs = _policy(tmp_path, memory)
    sampler = NumpyActorCritic(sampling_copy(policy), np.random.default_rng(3))
    sampler.reset_noise(len(obs))
    action, value, log_prob = sampler(obs)
    assert action.dtype == np.float32 and action.shape == (64, 4)
    with torch.no_grad():
        t_obs = torch.as_tensor(obs)
        t_value, t_log_prob, _ = policy.evaluate_actions(t_obs, torch.as_tensor(action))
        dist = policy.get_distribution(t_obs).distribution
    assert np.allclose(value, t_value.numpy().ravel(), atol=1e-5)
    assert np.allclose(log_prob, t_log_prob.numpy(), atol=1e-4)
    assert np.allclose(sampler.values(obs), value)
    # the noise: centred on the policy's mean, with its spread (one observation, 20k draws)
    one = np.repeat(obs[:1], 20000, axis=0)
    sampler.reset_noise(len(one))
    drawn = sampler(one)[0]
    mean, spread = dist.mean.numpy()[0], dist.stddev.numpy()[0]
    assert np.allclose(drawn.mean(axis=0), mean, atol=0.05 * spread.max())
    assert np.allclose(drawn.std(axis=0), spread, rtol=0.05)
    # and a new load takes the policy's new weights
    with torch.no_grad():
        for p in policy.parameters():
            p.add_(0.1 * torch.randn_like(p))
    sampler.load({k: v.clone() for k, v in policy.state_dict().items()})
    with torch.no_grad():
        t_value = policy.predict_values(t_obs).numpy().ravel()
    assert np.allclose(sampler.values(obs), t_value, atol=1e-5)


def test_gsde_keeps_each_envs_noise_map_until_it_is_drawn_anew(tmp_path):
    policy, obs = _policy(tmp_path)
    sampler = NumpyActorCritic(sampling_copy(policy), np.random.default_rng(3))
    sampler.reset_noise(4)
    first, again = sampler(obs[:4])[0], sampler(obs[:4])[0]
    assert np.array_equal(first, again)  # one map per env: the same state, the same push
    sampler.reset_noise(4)
    assert not np.allclose(sampler(obs[:4])[0], first)
