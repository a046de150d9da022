"""One env process's share of ``train ppo``'s sampling, in this process: ``N`` c172p altitude
envs (10 Hz) sampled by the numpy policy (``rl.grouped.sampling.sample_rollout``, a fresh
MLP), beside a bare JSBSim loop of the same agent steps (``benchmarks.physics.raw_loop``),
three rounds; with ``--profile``, cProfile's top functions of one more rollout; with
``--parts``, the time of each part of the loop's step (the actor's pass, the clip, the envs'
steps, the rest), measured inside the loop, and the same loop with a fixed action in place of
the actor.

    PYTHONPATH=. python docs/experiments/rl_sampling_profile.py [--envs 4] [--profile] [--parts]

The results: docs/experiments/rl-sessions.md, Speed.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

from benchmarks.physics import raw_loop
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.modeling_mlp import MLPPolicy
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.envs import make_env
from gymfg_il.rl.grouped.sampling import install, sample_rollout, sampling_copy, step_env
from gymfg_il.rl.model import make_model

STEPS = 2000  # steps of each env a round


def parts(policy: Any, envs: list[Any], obs: np.ndarray, steps: int, actor: bool) -> str:
    """µs an env step of each part of ``sample_rollout``'s step, timed inside the loop
    (``actor`` False: a fixed action, no network)."""
    space = envs[0].action_space
    fixed = np.zeros((len(envs), 4), dtype=np.float32)
    fixed[:, 3] = 0.75
    spent = dict.fromkeys(("actor", "clip", "envs", "rest"), 0.0)
    policy.reset_noise(len(envs))
    for t in range(steps):
        a = time.perf_counter()
        if t % 4 == 0:
            policy.reset_noise(len(envs))
        action = policy.sample(obs)[0] if actor else fixed
        b = time.perf_counter()
        clipped = np.clip(action, space.low, space.high)
        c = time.perf_counter()
        out = [step_env(env, x) for env, x in zip(envs, clipped, strict=True)]
        d = time.perf_counter()
        np.array([o[1] for o in out]), np.array([o[2] for o in out])
        obs = np.stack([o[0] for o in out])
        spent["rest"] += time.perf_counter() - d
        spent["actor"] += b - a
        spent["clip"] += c - b
        spent["envs"] += d - c
    each = {k: v / (steps * len(envs)) * 1e6 for k, v in spent.items()}
    shown = ", ".join(f"{k} {v:.1f}" for k, v in each.items())
    return f"{'actor' if actor else 'fixed action'}: {shown}; all {sum(each.values()):.1f} µs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--envs", type=int, default=4, help="envs in the process")
    parser.add_argument("--profile", action="store_true", help="print cProfile's top 30")
    parser.add_argument("--parts", action="store_true", help="time each part of a step")
    args = parser.parse_args()
    flight = FlightSpec.solo("c172p", "altitude")
    probe = flight.make_env()
    n_obs = probe.observation_space.shape[0]
    probe.close()
    stats = [{"mean": np.zeros(n), "std": np.ones(n)} for n in (n_obs, 4)]
    env_fn = partial(make_env, flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.2)
    venv = VecNormalize(DummyVecEnv([env_fn]), norm_obs=False, norm_reward=True)
    cfg = PPORunConfig(init=Path("unused"), envs=1, rollout_steps=64, batch_size=64)
    module = MLPPolicy(MLPConfig(), *stats)
    model = make_model(cfg, venv, module, Path(tempfile.mkdtemp()), "cpu", flight.agent_hz)
    policy = install(sampling_copy(model.policy), 0)
    weights = {k: v.detach().cpu() for k, v in model.policy.state_dict().items()}
    envs = [env_fn() for _ in range(args.envs)]
    obs = np.stack([env.reset(seed=i)[0] for i, env in enumerate(envs)])
    sample_rollout(policy, envs, obs, weights, 200, 4)  # warm
    raw = raw_loop()
    for r in range(3):
        start = time.perf_counter()
        sample_rollout(policy, envs, obs, weights, STEPS, 4)
        sampled = (time.perf_counter() - start) / (STEPS * args.envs)
        start = time.perf_counter()
        raw(STEPS)
        bare = (time.perf_counter() - start) / STEPS
        print(
            f"round {r}: sampling {sampled * 1e6:.1f} µs an env step, bare JSBSim "
            f"{bare * 1e6:.1f} µs a step, ratio {bare / sampled:.2f}"
        )
    if args.parts:
        for actor in (True, False, True, False):
            print(parts(policy, envs, obs, STEPS, actor))
    if args.profile:
        profile = cProfile.Profile()
        profile.enable()
        sample_rollout(policy, envs, obs, weights, STEPS, 4)
        profile.disable()
        pstats.Stats(profile).sort_stats("tottime").print_stats(30)


if __name__ == "__main__":
    main()
