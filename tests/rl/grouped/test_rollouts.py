"""The grouped sampler fills stable-baselines3's rollout buffer as stable-baselines3's own
``collect_rollouts`` does (``train ppo --sampler grouped`` against ``--sampler sb3``): on the
same seeds, the same observations, actions, rewards, episode starts, values, log-probabilities,
returns and advantages, bit for bit where no arithmetic differs (the first observations, the
episode starts and lengths, the verdicts) and to float tolerance where numpy computes what
torch does."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest
import torch

pytest.importorskip("stable_baselines3")

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.modeling_mlp import MLPPolicy
from gymfg_il.rl import reward
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.envs import make_env, training_envs
from gymfg_il.rl.grouped.algorithm import GroupedPPO
from gymfg_il.rl.grouped.vec import GroupedVecEnv
from gymfg_il.rl.model import make_model

BUFFER = ("observations", "actions", "rewards", "values", "log_probs", "returns", "advantages")


def _model(n_envs, tmp_path, sampler="grouped", episode_time_s=3.0):
    """PPO around a fresh MLP (seed 0) on ``n_envs`` envs as ``sampler`` samples them (the
    grouped envs in 2 processes), seeded and reset as ``train ppo`` does."""
    flight = FlightSpec.solo("c172p", "altitude", episode_time_s=episode_time_s)
    n_obs = flight.make_env().observation_space.shape[0]
    torch.manual_seed(0)
    stats = [{"mean": np.zeros(n), "std": np.ones(n)} for n in (n_obs, 4)]
    module = MLPPolicy(MLPConfig(hidden=[32, 32]), *stats)
    fn = partial(make_env, flight.to_dict(), [0.0, 0.0, 0.0, 0.5], [0.3, 0.3, 0.3, 0.3], 0.2)
    venv = (
        GroupedVecEnv([fn] * n_envs, 2)
        if sampler == "grouped"
        else training_envs(fn, n_envs, "sb3")
    )
    venv.seed(5)
    venv = reward.normalize(venv, 0.99)
    cfg = PPORunConfig(
        task="altitude", aircraft="c172p", envs=n_envs, rollout_steps=40, batch_size=40,
        seed=2, sampler=sampler,
    )  # fmt: skip
    model = make_model(cfg, venv, module, tmp_path, "cpu", flight.agent_hz)
    from stable_baselines3.common.logger import Logger

    model.set_logger(Logger(folder=None, output_formats=[]))  # no log folder, none in /tmp
    _, callback = model._setup_learn(10**6, callback=None)
    return model, callback


def _collect(model, callback):
    assert model.collect_rollouts(model.env, callback, model.rollout_buffer, model.n_steps)
    return model.rollout_buffer


def test_the_grouped_sampler_fills_the_buffer_stable_baselines3s_own_loop_fills(tmp_path):
    # 3 s episodes: the 40 steps of each of 3 envs cross a time limit's cut, whose value is
    # bootstrapped, and an auto-reset. The policy's spread is ~0 (the log-probability then is
    # that of the mean, whatever the draw), so both sample its mean
    runs = []
    for sampler in ("sb3", "grouped"):
        model, callback = _model(3, tmp_path / sampler, sampler)
        assert isinstance(model, GroupedPPO) == (sampler == "grouped")
        with torch.no_grad():
            model.policy.log_std.fill_(-30.0)
        runs.append((model, _collect(model, callback)))
        model.env.close()
    (own, a), (grouped, b) = runs
    assert a.episode_starts[1:].sum() >= 3  # every env reset within the rollout
    for key in BUFFER:
        assert np.allclose(getattr(a, key), getattr(b, key), rtol=1e-4, atol=1e-4), key
    assert np.array_equal(a.observations[0], b.observations[0])  # the seeded resets
    assert np.array_equal(a.episode_starts, b.episode_starts)  # the dones, step by step
    assert np.array_equal(own._last_episode_starts, grouped._last_episode_starts)
    assert own.num_timesteps == grouped.num_timesteps == 120
    assert [e["l"] for e in own.ep_info_buffer] == [e["l"] for e in grouped.ep_info_buffer]
    assert list(own.ep_success_buffer) == list(grouped.ep_success_buffer)
    assert np.allclose(own.env.ret_rms.var, grouped.env.ret_rms.var, rtol=1e-4)


@pytest.mark.slow
def test_every_rollout_samples_the_policy_as_it_is_now(tmp_path):
    model, callback = _model(4, tmp_path, episode_time_s=90.0)
    try:
        for _ in range(2):
            buffer = _collect(model, callback)
            obs = torch.as_tensor(buffer.observations.reshape(-1, buffer.obs_shape[0]))
            actions = torch.as_tensor(buffer.actions.reshape(-1, 4))
            with torch.no_grad():
                values, log_prob, _ = model.policy.evaluate_actions(obs, actions)
            assert np.allclose(values.numpy().ravel(), buffer.values.ravel(), atol=1e-5)
            assert np.allclose(log_prob.numpy(), buffer.log_probs.ravel(), atol=1e-4)
            # an update in between: the env processes must sample the new weights
            with torch.no_grad():
                for p in model.policy.actor.parameters():
                    p.add_(0.05 * torch.randn_like(p))
    finally:
        model.env.close()
