"""RL sampling (``train ppo``): stable-baselines3's PPO collecting rollouts (policy inference
included) from N envs in one process per core, each sampling its envs' actions itself
(``rl.vec``, as ``train ppo`` runs them, the policy as numpy functions: ``rl.forward``),
against the physics it cannot beat: min(N, cores) bare JSBSim loops doing the same agent
steps (c172p altitude, 10 Hz = 12 JSBSim frames).

    python -m benchmarks.rl [--envs 2 8 16]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path

from benchmarks.common import Row, print_rows
from benchmarks.physics import raw_loop


def sampler(n_envs: int) -> tuple[Callable[[int], None], Callable[[], None]]:
    """(collect about ``steps`` env steps with PPO's own rollout loop, close) for PPO around
    a fresh MLP on ``n_envs`` envs, grouped in one process per core as ``train ppo`` runs them."""
    import tempfile
    from functools import partial

    import numpy as np
    from stable_baselines3.common.vec_env import VecNormalize

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.policies.configuration_mlp import MLPConfig
    from gymfg_il.policies.modeling_mlp import MLPPolicy
    from gymfg_il.rl.config import PPORunConfig
    from gymfg_il.rl.env import make_env
    from gymfg_il.rl.run import make_model
    from gymfg_il.rl.vec import training_envs

    flight = FlightSpec.solo("c172p", "altitude")
    env = flight.make_env()
    n_obs = env.observation_space.shape[0]
    env.close()
    stats = [{"mean": np.zeros(n), "std": np.ones(n)} for n in (n_obs, 4)]
    module = MLPPolicy(MLPConfig(), *stats)
    env_fn = partial(make_env, flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.2)
    venv = training_envs(env_fn, n_envs)
    venv.seed(0)
    venv = VecNormalize(venv, norm_obs=False, norm_reward=True)
    cfg = PPORunConfig(init=Path("unused"), envs=n_envs, rollout_steps=64, batch_size=64)
    model = make_model(cfg, venv, module, Path(tempfile.mkdtemp()), "cpu", flight.agent_hz)
    model.tensorboard_log = None
    _, callback = model._setup_learn(10**9, callback=None)

    def collect(steps: int) -> None:
        per_env = max(1, steps // n_envs)
        model.rollout_buffer.buffer_size = per_env
        model.rollout_buffer.reset()
        model.collect_rollouts(venv, callback, model.rollout_buffer, per_env)

    return collect, venv.close


def sampling_vs_bound(n_envs: int, steps: int, rounds: int) -> Row:
    """Paired rounds: PPO sampling with ``n_envs`` envs, and one bare JSBSim loop (times
    min(n_envs, cores): the bound with every core on physics)."""
    import statistics

    import torch

    cores = len(os.sched_getaffinity(0))
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # as train ppo runs it
    collect, close = sampler(n_envs)
    raw = raw_loop()
    collect(steps // 4)  # the workers warm
    ratios, rl, physics = [], [], []
    try:
        for i in range(rounds):
            order = (collect, raw) if i % 2 == 0 else (raw, collect)
            rates = {}
            for fn in order:
                n = steps if fn is collect else steps // 2
                t0 = time.perf_counter()
                fn(n)
                rates[fn] = n / (time.perf_counter() - t0)
            bound = rates[raw] * min(n_envs, cores)
            rl.append(rates[collect])
            physics.append(bound)
            ratios.append(rates[collect] / bound)
    finally:
        close()
        torch.set_num_threads(threads)
    own = n_envs == cores  # the row by its name: as many envs as cores
    return Row(
        "rl_sampling_vs_physics_bound" + ("" if own else f"_{n_envs}_envs"),
        statistics.median(ratios),
        "ratio",
        0.8,
        detail=[
            f"PPO sampling, {n_envs} envs            {statistics.median(rl):9,.0f} steps/s",
            f"bound: {min(n_envs, cores)} x bare JSBSim      "
            f"{statistics.median(physics):9,.0f} steps/s",
        ],
        extra={"rounds": ratios, "envs": n_envs, "cores": cores},
    )


def rows(quick: bool, envs: tuple[int, ...] | None = None) -> list[Row]:
    cores = len(os.sched_getaffinity(0))
    chosen = envs or ((cores,) if quick else (cores, 4 * cores))
    steps, rounds = (1024, 2) if quick else (8192, 5)
    return [sampling_vs_bound(n, steps, rounds) for n in chosen]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--envs", type=int, nargs="+", help="env counts (default: cores, 4 x cores)")
    p.add_argument("--quick", action="store_true")
    args = p.parse_args(argv)
    print_rows(rows(args.quick, tuple(args.envs) if args.envs else None))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
