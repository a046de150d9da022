"""A PPO run, from start to saved policy (``train_ppo``, ``train ppo``).

The actor starts as the cloned MLP (``rl.start``, ``rl.policy``); the envs are the policy's
own flight, changed where the run's flight options say so, seeded per env so that a run
repeats (``rl.envs``), their reward composed in ``rl.reward``. Every ``eval_every`` env steps
the actor's mean action flies the same held-out seeds (``rl.callbacks``, ``rl.judge``); the
first evaluation, before any update, is the starting policy, and the controller flies those
seeds once beside it. The algorithm is stable-baselines3's PPO with the fine-tuning's warm-up,
ramp and anchor (``rl.algorithm``, ``rl.model``), sampled by stable-baselines3's own loop or
the grouped sampler (``rl.grouped``). The result is one of our policy checkpoints (type
``ppo``), with its learning curve and TensorBoard log (``rl.saving``).

With more than one env, the env processes start by forkserver: a script that calls
``train_ppo`` runs it under ``if __name__ == "__main__":``.
"""

from __future__ import annotations

import os
import shutil
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import torch

from gymfg_il.rl import reward
from gymfg_il.rl.callbacks import EvaluationCallback
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.envs import make_env, training_envs
from gymfg_il.rl.folders import out_folder, scratch_folder
from gymfg_il.rl.judge import EvalPoint, Judge, choose
from gymfg_il.rl.model import make_model
from gymfg_il.rl.saving import PPOResult, save_run
from gymfg_il.rl.start import Start, starting_policy, stats_of
from gymfg_il.workers import Workers

__all__ = ["PPOResult", "train_ppo"]


def train_ppo(
    cfg: PPORunConfig,
    on_steps: Callable[[int], None] | None = None,
    on_eval: Callable[[EvalPoint], None] | None = None,
    start: Start | None = None,
) -> PPOResult:
    """Fine-tune (or train from scratch), evaluating as it goes, and save the policy, its
    curve and TensorBoard log under ``cfg.out``. ``on_steps(n)``: n more env steps sampled;
    ``on_eval``: each evaluation, the first (the start) before any update."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # small networks: one thread is fastest, and repeatable
    try:
        return _train(cfg, on_steps, on_eval, start or starting_policy(cfg))
    finally:
        torch.set_num_threads(threads)


def _train(
    cfg: PPORunConfig,
    on_steps: Callable[[int], None] | None,
    on_eval: Callable[[EvalPoint], None] | None,
    start: Start,
) -> PPOResult:
    flight, module = start.flight, start.module
    out = out_folder(cfg.out, cfg.init, flight)  # checked before training, not after
    seeds = list(range(cfg.eval_seed, cfg.eval_seed + cfg.eval_episodes))
    more = list(range(seeds[-1] + 1, cfg.eval_seed + cfg.chosen_on))
    began = time.perf_counter()
    scratch_dir = scratch_folder()  # removed below; a killed run's, by a later run
    # the evaluations' processes, started before the envs' (the env processes wait while an
    # evaluation flies)
    pool = Workers(min(2, len(os.sched_getaffinity(0)))) if more else Workers(1)
    judge = Judge(flight, seeds, start, scratch_dir, began, more, pool, cfg.checkpoints)
    try:
        controller = judge.controller()
        curve = [judge(module, 0)]
        if on_eval:
            on_eval(curve[0])
        callback = EvaluationCallback(
            judge, curve, cfg.eval_every, cfg.keep == "best", on_steps, on_eval
        )
        model = _learn(cfg, start, callback, scratch_dir / "tensorboard")
        last = model.policy.actor  # after the last update, which no evaluation has seen
        curve.append(judge(last, model.num_timesteps, more=cfg.keep == "best"))
        if on_eval:
            on_eval(curve[-1])
        kept, actor = choose(cfg.keep, judge, curve, last)
        seconds = time.perf_counter() - began
        result = PPOResult(out, model.num_timesteps, seconds, curve, controller, start.notes, kept)
        save_run(cfg, result, start, actor, scratch_dir)
        return result
    finally:
        pool.close()
        shutil.rmtree(scratch_dir, ignore_errors=True)


def _learn(cfg: PPORunConfig, start: Start, callback: Any, tensorboard: Path) -> Any:
    """The model after ``cfg.steps`` env steps of PPO from ``start``, in its training envs
    (closed when it is done), with ``callback`` and its TensorBoard log in ``tensorboard``."""
    from gymfg_il.learning.config import resolve_device

    flight, module = start.flight, start.module
    action = stats_of(module, "action_norm")
    env_fn = partial(
        make_env,
        flight.to_dict(),
        action["mean"].tolist(),
        action["std"].tolist(),
        cfg.ppo.success_bonus,
        module.memory_maker(),  # None without memory: the flight's observation alone
    )
    venv = training_envs(env_fn, cfg.n_envs, cfg.sampler)
    venv.seed(cfg.seed)  # env k's first reset takes seed + k
    gamma, _ = cfg.discounts(flight.agent_hz)
    venv = reward.normalize(venv, gamma)
    try:
        device = resolve_device(cfg.device)
        model = make_model(cfg, venv, module, tensorboard, device, flight.agent_hz)
        model.learn(cfg.steps, callback=callback, tb_log_name="ppo", progress_bar=False)
        model.logger.close()
    finally:
        venv.close()
    return model
