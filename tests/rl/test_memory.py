"""PPO on a policy with a memory (``train bc --memory vertical``): the envs PPO samples give the
observation extended by the memory the policy computes in flight (``rl.envs.Remembering``),
the actor starts as the cloned policy at every step of an episode, with either sampler, and
the saved policy keeps its memory, which eval and DAgger fly it with."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from gymfg_il.policies.memory import names_of
from gymfg_il.rl.config import PPORunConfig

pytest.importorskip("stable_baselines3")

K = len(names_of("vertical"))  # the memory's columns, the observation's last
# the grouped sampler's numpy pass against torch on one row, in float32 epsilons of the
# largest normalised mean action: numpy's and torch's matrix products sum in other orders.
# Measured over eight whole episodes: 1.1 eps (9.5e-7 at 7.4) with --memory vertical, 3.1
# (1.5e-5 at 41.7) with loops; the no-memory pass rounds alike (tests/rl/grouped)
NUMPY_VS_TORCH_EPS = 8


def _argv(init, out, *more):
    """``train ppo``'s command line for a short run whose saved actor is the last one."""
    return [
        "ppo", "--init", str(init), "--out", str(out), "--steps", "1024", "--envs", "2",
        "--rollout-steps", "256", "--batch-size", "128", "--epochs", "2", "--eval-every", "1024",
        "--eval-episodes", "2", "--select-episodes", "2", "--critic-warmup", "256", "--seed", "3",
        "--keep", "last", "--no-progress", *more,
    ]  # fmt: skip


def test_the_actor_starts_as_the_remembering_policy_at_every_step(remembering_bc, tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv

    from gymfg_il.policies.checkpoint import load_policy
    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.grouped.forward import NumpyActorCritic
    from gymfg_il.rl.grouped.sampling import sampling_copy
    from gymfg_il.rl.model import make_model
    from gymfg_il.rl.start import starting_policy, stats_of

    cfg = PPORunConfig(init=remembering_bc, out=tmp_path / "ppo", envs=1)
    start = starting_policy(cfg)
    action, fresh = stats_of(start.module, "action_norm"), start.module.memory_maker()
    spec = start.flight.to_dict()
    venv = DummyVecEnv([lambda: make_env(spec, action["mean"], action["std"], 0.0, fresh)])
    try:
        model = make_model(cfg, venv, start.module, tmp_path / "tb", "cpu", start.flight.agent_hz)
        env = venv.envs[0]
        assert env.observation_space.shape == (start.module.n_obs,)
        bc, _ = load_policy(remembering_bc)
        sampler = NumpyActorCritic(sampling_copy(model.policy), np.random.default_rng(0))
        sampler.reset_noise(1)
        gap, largest = 0.0, 1.0
        for seed in (5, 6):  # the second episode's memory starts afresh, as the policy's
            obs, _ = env.reset(seed=seed)
            state = None
            for _ in range(60):
                # the BC policy's memory, as it computes it in flight (``act``)
                seen, state = bc.remember(torch.as_tensor(obs[None, :-K]), state)
                assert torch.equal(seen[0], torch.as_tensor(obs))
                batch = torch.as_tensor(obs[None])
                with torch.no_grad():
                    mean = model.policy.get_distribution(batch).distribution.mean
                    assert torch.equal(mean, bc(batch))  # bit for bit, normalised
                gap = max(gap, float(np.abs(sampler.sample(obs[None])[1] - mean.numpy()).max()))
                largest = max(largest, float(mean.abs().max()))
                obs = env.step(mean.numpy()[0])[0]
            assert np.abs(obs[-K:]).min() > 0.1  # the memory moved
        assert gap <= NUMPY_VS_TORCH_EPS * np.finfo(np.float32).eps * largest
    finally:
        venv.close()


def _flies_with_its_memory(path, flight, seed=11):
    """``path``'s policy flown as eval flies it: its actions are its network's on each
    observation and its memory from the episode's start, and not those of no memory."""
    from gymfg_il.policies.checkpoint import load_policy
    from gymfg_il.rollout.agents import AgentSpec
    from gymfg_il.rollout.seeded import fly_many

    (episode,) = fly_many(flight, AgentSpec.policy(path), [seed])
    rows = np.asarray(episode.solo.observations, dtype=np.float32)
    policy, _ = load_policy(path)
    x = torch.as_tensor(np.c_[rows, policy.memory_maker()().over(rows)])
    gaps = []
    for memory in (x[:, -K:].clone(), torch.zeros(len(x), K)):
        x[:, -K:] = memory
        with torch.no_grad():
            again = policy.action_norm.inverse(policy(x)).double().numpy()
        gaps.append(np.abs(np.clip(again, -1, 1)[:, :3] - episode.solo.actions[:, :3]).max())
    # one row flown against many at once: MKL sums them in other orders (tests/conftest.py,
    # STEP_VS_WINDOW_ATOL); the memory itself is exact
    assert gaps[0] <= 1e-6
    assert gaps[1] > 1e-3


@pytest.mark.slow  # PPO runs
def test_a_fine_tune_of_a_remembering_policy_keeps_its_memory_and_repeats(remembering_bc, tmp_path):
    from safetensors.torch import load_file

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.evaluation.runner import evaluate
    from gymfg_il.learning.dagger import retrain_config
    from gymfg_il.rl.judge import EvalPoint
    from gymfg_il.rollout.agents import AgentSpec
    from gymfg_il.train import main

    for name in ("a", "b"):
        assert main(_argv(remembering_bc, tmp_path / name)) == 0
    config = json.loads((tmp_path / "a" / "config.json").read_text())
    bc = json.loads((remembering_bc / "config.json").read_text())
    assert config["type"] == "ppo"
    assert config["policy"] == {**bc["policy"], "type": "ppo"}  # the memory kept
    assert config["memory_names"] == bc["memory_names"] == list(names_of("vertical"))
    assert config["observation_names"] == bc["observation_names"]  # the env's own
    runs = [load_file(str(tmp_path / name / "model.safetensors")) for name in ("a", "b")]
    start = load_file(str(remembering_bc / "model.safetensors"))
    assert set(runs[0]) == set(start) and "integral.weight" in start
    assert all(torch.equal(runs[0][k], runs[1][k]) for k in start)  # a seeded run repeats
    assert not all(torch.equal(runs[0][k], start[k]) for k in start)  # the actor learnt
    # the curve's start is the BC policy as eval flies it, memory and all
    flight = FlightSpec.from_dict(config["spec"])
    first = EvalPoint(**config["rl"]["curve"][0])
    rows, _ = evaluate(flight, {"bc": AgentSpec.policy(remembering_bc)}, [7000, 7001])
    assert (rows[0]["success_rate"], rows[0]["mean_return"]) == (first.success, first.mean_return)
    _flies_with_its_memory(tmp_path / "a", flight)
    # DAgger trains it again as the MLP it is, with its memory
    again = retrain_config(config, remembering_bc, tmp_path / "again")
    assert (again.policy.type, again.policy.memory) == ("mlp", "vertical")


@pytest.mark.slow  # PPO runs
def test_stable_baselines3s_own_sampler_fine_tunes_a_remembering_policy(remembering_bc, tmp_path):
    from safetensors.torch import load_file

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.train import main

    out = tmp_path / "sb3"
    assert main(_argv(remembering_bc, out, "--sampler", "sb3")) == 0
    config = json.loads((out / "config.json").read_text())
    assert config["rl"]["settings"]["sampler"] == "sb3"
    assert config["policy"]["memory"] == "vertical" and config["memory_names"]
    saved = load_file(str(out / "model.safetensors"))
    start = load_file(str(remembering_bc / "model.safetensors"))
    assert not all(torch.equal(saved[k], start[k]) for k in start)  # the actor learnt
    _flies_with_its_memory(out, FlightSpec.from_dict(config["spec"]))


def test_a_policy_without_memory_is_saved_as_before(bc_policy):
    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.start import as_ppo, meta_of, starting_policy

    start = starting_policy(PPORunConfig(init=bc_policy))
    assert start.module.memory_maker() is None
    assert as_ppo(start.module).config.to_dict() == {
        "type": "ppo",
        "hidden": [256, 256],
        "dropout": 0.0,
        "memory": "none",  # chosen by train bc (--memory auto chose none or was told so)
    }
    assert "memory_names" not in meta_of(start)
    env = make_env(start.flight.to_dict(), [0.0] * 4, [1.0] * 4)
    assert env.observation_space.shape == (start.module.n_obs,)  # the flight's own


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped")  # the wrapper is checked
def test_the_remembering_env_keeps_gymnasiums_contract(remembering_bc):
    from gymnasium.utils.env_checker import check_env

    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.start import starting_policy

    start = starting_policy(PPORunConfig(init=remembering_bc))
    env = make_env(start.flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.0, start.module.memory_maker())
    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    assert obs.dtype == np.float32 and obs.shape == (start.module.n_obs,)
    assert np.all(np.isfinite(env.observation_space.high[-K:]))  # the integrals' clamps
    env.close()
