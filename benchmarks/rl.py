"""RL sampling (``train ppo``): stable-baselines3's PPO collecting rollouts (policy inference
included) from N envs with the grouped sampler, in one process per core, each sampling its
envs' actions itself (``rl.grouped``, as ``train ppo`` runs them by default, the policy as
numpy functions), against the physics it cannot beat: min(N, cores) bare JSBSim loops doing
the same agent steps (c172p altitude, 10 Hz = 12 JSBSim frames). Beside it, in the same
rounds, the ceiling any sampler has here: the same training envs in as many processes,
sampled by the same loop (``rl.grouped.sampling.sample_rollout``) with a fixed action, no
policy at all (``rl_envs_alone_vs_physics_bound``), and the sampling over that ceiling
(``rl_sampling_vs_envs_alone``: the policy's share; the row without a suffix is train ppo's
default count, four envs a core). Rows name their env count unless it is the cores' (``_8_envs``).
``--sampler sb3`` measures stable-baselines3's own loop instead (``train ppo --sampler sb3``;
its rows end in ``_sb3``).

    python -m benchmarks.rl [--envs 2 8 16] [--sampler sb3]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from benchmarks.common import Row, print_rows
from benchmarks.physics import raw_loop


def sampler(n_envs: int, kind: str = "grouped") -> tuple[Callable[[int], None], Callable[[], None]]:
    """(collect about ``steps`` env steps with PPO's rollout loop, close) for PPO around a
    fresh MLP on ``n_envs`` envs, sampled as ``train ppo --sampler KIND`` samples them."""
    import tempfile
    from functools import partial

    import numpy as np
    from stable_baselines3.common.vec_env import VecNormalize

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.policies.configuration_mlp import MLPConfig
    from gymfg_il.policies.modeling_mlp import MLPPolicy
    from gymfg_il.rl.config import PPORunConfig
    from gymfg_il.rl.envs import make_env, training_envs
    from gymfg_il.rl.model import make_model

    flight = FlightSpec.solo("c172p", "altitude")
    env = flight.make_env()
    n_obs = env.observation_space.shape[0]
    env.close()
    stats = [{"mean": np.zeros(n), "std": np.ones(n)} for n in (n_obs, 4)]
    module = MLPPolicy(MLPConfig(), *stats)
    env_fn = partial(make_env, flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.2)
    venv = training_envs(env_fn, n_envs, kind)
    venv.seed(0)
    venv = VecNormalize(venv, norm_obs=False, norm_reward=True)
    cfg = PPORunConfig(
        init=Path("unused"), envs=n_envs, rollout_steps=64, batch_size=64, sampler=kind
    )
    model = make_model(cfg, venv, module, Path(tempfile.mkdtemp()), "cpu", flight.agent_hz)
    model.tensorboard_log = None
    _, callback = model._setup_learn(10**9, callback=None)

    def collect(steps: int) -> None:
        per_env = max(1, steps // n_envs)
        model.rollout_buffer.buffer_size = per_env
        model.rollout_buffer.reset()
        model.collect_rollouts(venv, callback, model.rollout_buffer, per_env)

    return collect, venv.close


class _FixedActions:
    """``rl.grouped.sampling.sample_rollout``'s policy with no network: the same action for
    every env at every step, values and log-probabilities 0."""

    action = (0.0, 0.0, 0.0, 0.75)

    def load(self, weights: Any) -> None:
        pass

    def reset_noise(self, n: int) -> None:
        pass

    def sample(self, obs: Any) -> tuple[Any, Any]:
        import numpy as np

        actions = np.tile(np.array(self.action, np.float32), (len(obs), 1))
        return actions, actions

    def values(self, obs: Any) -> Any:
        import numpy as np

        return np.zeros(len(obs), np.float32)

    def score(self, obs: Any, actions: Any, mu: Any) -> tuple[Any, Any]:
        return self.values(obs), self.values(obs)


def _stepper(remote: Any, env_fn: Callable[[], Any], n: int, first_seed: int) -> None:
    """An env process with no policy: ``n`` envs from ``env_fn`` sampled by
    ``rl.grouped.sampling.sample_rollout`` (the loop ``train ppo``'s env processes run) with a fixed
    action, ``k`` steps each time it is sent ``k``; None ends it."""
    import numpy as np

    from gymfg_il.rl.grouped.sampling import sample_rollout

    envs = [env_fn() for _ in range(n)]
    obs = np.stack([env.reset(seed=first_seed + i)[0] for i, env in enumerate(envs)])
    fixed = _FixedActions()
    while (steps := remote.recv()) is not None:
        obs = sample_rollout(fixed, envs, obs, None, steps, -1)["last_obs"]  # type: ignore[arg-type]
        remote.send(len(obs))
    for env in envs:
        env.close()


def envs_alone(n_envs: int) -> tuple[Callable[[int], None], Callable[[], None]]:
    """(step about ``steps`` env steps with no policy, close): ``n_envs`` training envs (as
    ``sampler``'s) in one process per core, grouped as ``train ppo`` groups them."""
    import multiprocessing as mp
    from functools import partial

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.grouped.vec import groups_of

    flight = FlightSpec.solo("c172p", "altitude")
    env_fn = partial(make_env, flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.2)
    ctx: Any = mp.get_context("forkserver")
    groups = groups_of(n_envs, len(os.sched_getaffinity(0)))
    remotes, processes = [], []
    for group in groups:
        remote, work = ctx.Pipe()
        process = ctx.Process(
            target=_stepper, args=(work, env_fn, len(group), group.start), daemon=True
        )
        process.start()
        remotes.append(remote)
        processes.append(process)

    def step(steps: int) -> None:
        for remote in remotes:
            remote.send(max(1, steps // n_envs))
        for remote in remotes:
            remote.recv()

    def close() -> None:
        for remote in remotes:
            remote.send(None)
        for process in processes:
            process.join(timeout=10)

    return step, close


def sampling_vs_bound(n_envs: int, steps: int, rounds: int, kind: str = "grouped") -> list[Row]:
    """Rounds of three, the order turning: PPO sampling with ``n_envs`` envs, the same envs
    with no policy (``envs_alone``), and one bare JSBSim loop (times min(n_envs, cores): the
    bound with every core on physics). Two rows: the sampling and the envs alone, over the
    bound."""
    import statistics

    import torch

    cores = len(os.sched_getaffinity(0))
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # as train ppo runs it
    collect, close = sampler(n_envs, kind)
    alone, close_alone = envs_alone(n_envs)
    raw = raw_loop()
    collect(steps // 4)  # the workers warm
    alone(steps // 4)
    ratios: dict[Callable[[int], None], list[float]] = {collect: [], alone: []}
    rates: dict[Callable[[int], None], list[float]] = {collect: [], alone: [], raw: []}
    try:
        for i in range(rounds):
            order = (collect, alone, raw)[i % 3 :] + (collect, alone, raw)[: i % 3]
            for fn in order:
                n = steps // 2 if fn is raw else steps
                t0 = time.perf_counter()
                fn(n)
                rates[fn].append(n / (time.perf_counter() - t0))
            bound = rates[raw][-1] * min(n_envs, cores)
            for fn in (collect, alone):
                ratios[fn].append(rates[fn][-1] / bound)
    finally:
        close()
        close_alone()
        torch.set_num_threads(threads)
    ratio_of_rounds = [c / a for c, a in zip(rates[collect], rates[alone], strict=True)]
    own = "" if n_envs == cores else f"_{n_envs}_envs"  # the row by its name: envs = cores
    own += "" if kind == "grouped" else f"_{kind}"
    default = n_envs == 4 * cores and kind == "grouped"  # train ppo's env count
    versus = "" if default else f"_{n_envs}_envs" + ("" if kind == "grouped" else f"_{kind}")
    bound = statistics.median(rates[raw]) * min(n_envs, cores)
    sampled, alone_rate = statistics.median(rates[collect]), statistics.median(rates[alone])
    detail = [
        f"PPO sampling ({kind}), {n_envs} envs  {sampled:9,.0f} steps/s",
        f"the envs alone, no policy   {alone_rate:9,.0f} steps/s  (the ceiling of any sampler)",
        f"bound: {min(n_envs, cores)} x bare JSBSim      {bound:9,.0f} steps/s  "
        f"(every core on physics, nothing else)",
    ]
    extra = {"envs": n_envs, "cores": cores}
    return [
        Row(
            "rl_sampling_vs_physics_bound" + own,
            statistics.median(ratios[collect]),
            "ratio",
            0.75,
            detail=detail,
            extra={"rounds": ratios[collect], **extra},
        ),
        Row(
            "rl_envs_alone_vs_physics_bound" + own,
            statistics.median(ratios[alone]),
            "ratio",
            0.85 if n_envs <= cores else 0.90,
            extra={"rounds": ratios[alone], **extra},
        ),
        Row(
            "rl_sampling_vs_envs_alone" + versus,
            statistics.median(ratio_of_rounds),
            "ratio",
            0.85 if default else None,
            detail=[f"bound: the envs alone, the same {n_envs} envs in the same rounds"],
            extra={"rounds": ratio_of_rounds, **extra},
        ),
    ]


def ppo_wall(steps: int) -> Row:
    """Minutes ``train ppo`` takes for 1M steps with default flags (its evaluations and the
    kept actor's choice included): the altitude in moderate turbulence from a clone of the
    bundled sample dataset (``train bc``, default flags), as docs/results/rl.md runs it.
    ``steps`` under 1M: that run's minutes scaled to 1M."""
    import subprocess
    import sys
    import tempfile

    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}

    def run(*argv: str) -> float:
        started = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", *argv, "--no-progress"], env=env, capture_output=True, text=True
        )
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(argv)} failed:\n{done.stderr[-2000:]}")
        return time.perf_counter() - started

    with tempfile.TemporaryDirectory() as tmp:
        dataset = root / "datasets/sample-altitude-c172p/dataset"
        run("gymfg_il.train", "bc", "--dataset", str(dataset), "--out", f"{tmp}/bc")
        wall = run(
            "gymfg_il.train", "ppo", "--init", f"{tmp}/bc", "--turbulence", "moderate",
            "--steps", str(steps), "--out", f"{tmp}/ppo",
        )  # fmt: skip
    scaled = wall * 1_000_000 / steps / 60
    how = "measured" if steps >= 1_000_000 else f"{steps:,} steps measured, scaled to 1M"
    return Row(
        "ppo_1m_steps_wall_min",
        scaled,
        "min",
        4.0,
        higher_is_better=False,
        detail=[
            f"train ppo, altitude from the sample's clone, moderate turbulence: {how} "
            f"({wall:.0f} s; evaluations every 50k steps included)"
        ],
    )


def rows(quick: bool, envs: tuple[int, ...] | None = None, kind: str = "grouped") -> list[Row]:
    cores = len(os.sched_getaffinity(0))
    chosen = envs or ((cores,) if quick else (cores, 4 * cores))
    steps, rounds = (1024, 3) if quick else (8192, 6)
    found = [row for n in chosen for row in sampling_vs_bound(n, steps, rounds, kind)]
    if envs is None and kind == "grouped":  # the whole run, as a user meets it
        found.append(ppo_wall(50_000 if quick else 1_000_000))
    return found


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--envs", type=int, nargs="+", help="env counts (default: cores, 4 x cores)")
    p.add_argument("--quick", action="store_true")
    p.add_argument(
        "--sampler", choices=("grouped", "sb3"), default="grouped", help="train ppo's --sampler"
    )
    args = p.parse_args(argv)
    print_rows(rows(args.quick, tuple(args.envs) if args.envs else None, args.sampler))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
