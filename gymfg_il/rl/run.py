"""PPO fine-tuning of a cloned policy with stable-baselines3 (``train ppo``).

The actor starts as the cloned MLP (``rl.policy``); the envs are the policy's own flight (its
aircraft, task, rate and episode time; the weather may be changed), several processes, seeded
per env so that a run repeats (``rl.env``). Every ``eval_every`` env steps the actor's mean
action flies the same held-out seeds (``rl.judge``); the first evaluation, before any update,
is the starting policy, and the controller flies those seeds once beside it. The envs run in
one process per core, each stepping its share of them (``rl.vec``). The result is
one of our policy checkpoints (type ``ppo``, the MLP's network), with its learning curve
(``curve.png``, ``curve.json``) and stable-baselines3's TensorBoard log (``tensorboard/``).

With more than one env, the env processes start by forkserver: a script that calls
``train_ppo`` runs it under ``if __name__ == "__main__":``.
"""

from __future__ import annotations

import json
import logging
import math
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import Any

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback

from gymfg_il.errors import ConfigError
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.env import make_env
from gymfg_il.rl.folders import out_folder, scratch_folder
from gymfg_il.rl.judge import EvalPoint, Judge, choose, plot_curve
from gymfg_il.rl.policy import AnchoredPolicy
from gymfg_il.rl.start import Start, as_ppo, meta_of, starting_policy, stats_of
from gymfg_il.rl.vec import GroupedVecEnv, training_envs
from gymfg_il.workers import Workers

log = logging.getLogger(__name__)


@dataclass
class PPOResult:
    out: Path
    steps: int
    seconds: float
    curve: list[EvalPoint]
    controller: EvalPoint
    notes: list[str]
    kept: EvalPoint  # the saved actor's evaluation (``PPORunConfig.keep``)

    @property
    def kept_step(self) -> int:
        """The step of the saved actor's evaluation."""
        return self.kept.step


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
    from stable_baselines3.common.vec_env import VecNormalize

    from gymfg_il.learning.config import resolve_device

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
        action = stats_of(module, "action_norm")
        env_fn = partial(
            make_env,
            flight.to_dict(),
            action["mean"].tolist(),
            action["std"].tolist(),
            cfg.success_bonus,
        )
        venv: Any = training_envs(env_fn, cfg.n_envs)
        venv.seed(cfg.seed)  # env k's first reset takes seed + k
        # rewards scaled by the running spread of the discounted return, never clipped (the
        # success bonus comes as one large reward)
        gamma, _ = cfg.discounts(flight.agent_hz)
        venv = VecNormalize(
            venv, norm_obs=False, norm_reward=True, gamma=gamma, clip_reward=math.inf
        )
        try:
            model = make_model(
                cfg,
                venv,
                module,
                scratch_dir / "tensorboard",
                resolve_device(cfg.device),
                flight.agent_hz,
            )
            watch = _Watch(cfg, judge, curve, on_steps, on_eval)
            model.learn(cfg.steps, callback=watch, tb_log_name="ppo", progress_bar=False)
            model.logger.close()
        finally:
            venv.close()
        last = model.policy.actor  # after the last update, which no evaluation has seen
        curve.append(judge(last, model.num_timesteps, more=cfg.keep == "best"))
        if on_eval:
            on_eval(curve[-1])
        kept, actor = choose(cfg.keep, judge, curve, last)
        seconds = time.perf_counter() - began
        result = PPOResult(out, model.num_timesteps, seconds, curve, controller, start.notes, kept)
        _save(cfg, result, start, actor, scratch_dir)
        return result
    finally:
        pool.close()
        shutil.rmtree(scratch_dir, ignore_errors=True)


class FineTunePPO(PPO):
    """stable-baselines3's PPO, holding the actor while the critic warms up (the first
    ``warmup`` env steps), then ramping the actor's learning rate up from 0 over ``ramp``
    env steps (Adam's first steps, with no history of the gradient, move every weight by
    about the full rate: a cloned network is knocked off its solution), and setting the
    anchor's weight before every update: ``anchor``, decaying linearly to 0 over ``span``
    env steps after the warm-up. On grouped envs its rollouts are sampled in the env
    processes (``collect_rollouts``)."""

    warmup, ramp, anchor, span, actor_scale = 0, 0, 0.0, 0, 1.0

    def train(self) -> None:
        policy = self.policy
        assert isinstance(policy, AnchoredPolicy)
        # the rollout this update learns from began at num_timesteps - n_steps x n_envs
        frozen = self.num_timesteps - self.n_steps * self.n_envs < self.warmup
        policy.freeze_actor(frozen)
        done = max(0, self.num_timesteps - self.warmup)
        weight = self.anchor * max(0.0, 1.0 - done / self.span) if self.span else 0.0
        policy.anchor_weight = weight
        share = min(1.0, done / self.ramp) if self.ramp else 1.0
        policy.optimizer.param_groups[0]["scale"] = self.actor_scale * share  # the actor's
        self.logger.record("train/actor_frozen", int(frozen))
        self.logger.record("train/anchor_weight", weight)
        rate = self.lr_schedule(self._current_progress_remaining)
        self.logger.record("train/actor_lr", rate * self.actor_scale * share)
        super().train()

    def collect_rollouts(
        self, env: Any, callback: Any, rollout_buffer: Any, n_rollout_steps: int
    ) -> bool:
        """stable-baselines3's rollout, sampled in the env processes when the envs are
        grouped (``GroupedVecEnv.rollout``): the same steps, rewards normalised, values
        bootstrapped, callbacks called and episodes logged step by step as its own
        ``collect_rollouts`` does, from the arrays the processes return."""
        import gymnasium as gym
        from stable_baselines3.common.vec_env import VecNormalize

        norm = env if isinstance(env, VecNormalize) else None
        grouped = norm.venv if norm is not None else env
        if not isinstance(grouped, GroupedVecEnv) or not isinstance(
            self.action_space, gym.spaces.Box
        ):
            return bool(super().collect_rollouts(env, callback, rollout_buffer, n_rollout_steps))
        assert self._last_episode_starts is not None
        self.policy.set_training_mode(False)
        rollout_buffer.reset()
        callback.on_rollout_start()
        got = grouped.rollout(self.policy, n_rollout_steps, self.seed or 0, self.sde_sample_freq)
        ends: dict[int, list[tuple[int, dict[str, Any]]]] = {}
        for t, i, info in got["ends"]:
            ends.setdefault(t, []).append((i, info))
        for t in range(n_rollout_steps):
            rewards, dones = got["rewards"][t], got["dones"][t]
            if norm is not None:
                if norm.training:
                    norm._update_reward(rewards)
                rewards = norm.normalize_reward(rewards)
                norm.returns[dones] = 0
            rewards = rewards + self.gamma * got["bootstrap"][t]
            infos: list[dict[str, Any]] = [{} for _ in range(env.num_envs)]
            for i, info in ends.get(t, []):
                infos[i] = info
            self.num_timesteps += env.num_envs
            callback.update_locals({"infos": infos, "dones": dones, "rewards": rewards})
            if not callback.on_step():
                return False
            self._update_info_buffer(infos, dones)
            rollout_buffer.add(
                got["obs"][t],
                got["actions"][t],
                rewards,
                self._last_episode_starts,
                torch.as_tensor(got["values"][t]),
                torch.as_tensor(got["log_probs"][t]),
            )
            self._last_episode_starts = dones
        self._last_obs = got["last_obs"]
        rollout_buffer.compute_returns_and_advantage(
            last_values=torch.as_tensor(got["last_values"]), dones=dones
        )
        callback.update_locals({"infos": infos, "dones": dones, "rewards": rewards})
        callback.on_rollout_end()
        return True


def make_model(
    cfg: PPORunConfig, venv: Any, module: Any, tensorboard: Path, device: str, agent_hz: int
) -> Any:
    """stable-baselines3's PPO with the cloned actor, the critic warm-up and the anchor, for
    a flight at ``agent_hz`` (the discount's rate)."""
    gamma, gae_lambda = cfg.discounts(agent_hz)
    # gSDE's noise on one control sums one term per observed variable (each of about unit
    # spread, normalised): its spread is about sqrt(n) x the matrix's
    sde_features = module.n_obs
    model = FineTunePPO(
        AnchoredPolicy,
        venv,
        learning_rate=cfg.lr,
        n_steps=cfg.rollout_steps,
        batch_size=cfg.batch_size,
        n_epochs=cfg.epochs,
        gamma=gamma,
        gae_lambda=gae_lambda,
        clip_range=cfg.clip_range,
        target_kl=cfg.target_kl or None,
        ent_coef=0.0,
        use_sde=True,
        sde_sample_freq=-1,  # a new noise map per rollout
        policy_kwargs={
            "start": module,
            "critic": list(cfg.critic),
            "actor_lr_scale": cfg.actor_rate / cfg.lr,
            "log_std_init": math.log(cfg.action_std / math.sqrt(sde_features)),
            "ortho_init": False,
        },
        tensorboard_log=str(tensorboard),
        seed=cfg.seed,
        device=device,
        verbose=0,
    )
    model.warmup, model.span = cfg.warmup_steps, cfg.anchor_span
    model.ramp = cfg.warmup_steps if cfg.init is not None else 0
    model.actor_scale = cfg.actor_rate / cfg.lr
    model.anchor = cfg.anchor if cfg.init is not None else 0.0  # from scratch: nothing to keep
    return model


class _Watch(BaseCallback):
    """stable-baselines3 callback: counts the steps and evaluates every ``eval_every``."""

    def __init__(
        self,
        cfg: PPORunConfig,
        judge: Judge,
        curve: list[EvalPoint],
        on_steps: Callable[[int], None] | None,
        on_eval: Callable[[EvalPoint], None] | None,
    ) -> None:
        super().__init__()
        self.cfg, self.judge, self.curve = cfg, judge, curve
        self.on_steps, self.on_eval = on_steps, on_eval
        self.next_eval = cfg.eval_every

    def _on_step(self) -> bool:
        if self.on_steps is not None:
            self.on_steps(self.training_env.num_envs)
        return True

    def _on_rollout_start(self) -> None:
        # after the update on the rollout that ended here (the last update is evaluated by
        # train_ppo, after learn)
        if self.num_timesteps < self.next_eval:
            return
        while self.next_eval <= self.num_timesteps:
            self.next_eval += self.cfg.eval_every
        policy = self.model.policy
        assert isinstance(policy, AnchoredPolicy)
        point = self.judge(policy.actor, self.num_timesteps, more=self.cfg.keep == "best")
        self.curve.append(point)
        self.logger.record("eval/success", point.success)
        self.logger.record("eval/mean_return", point.mean_return)
        self.logger.record("eval/crashed", point.crashed)
        if self.on_eval is not None:
            self.on_eval(point)


def _save(cfg: PPORunConfig, result: PPOResult, start: Start, actor: Any, scratch: Path) -> None:
    """The policy folder: config.json and model.safetensors (a ``ppo`` policy), the curve
    (curve.json, curve.png), the TensorBoard log and, if asked, every evaluated actor
    (checkpoints/), saved whole or not at all."""
    from gymfg_il.learning.saving import check_diverged
    from gymfg_il.policies.checkpoint import save_policy
    from gymfg_il.policies.checkpoint_folder import staged

    module = as_ppo(actor)
    check_diverged(module, f"lr={cfg.lr}", fix="lower --lr (default 3e-4)")
    flight = start.flight
    name = Path(result.out).name
    settings = {k: str(v) if isinstance(v, Path) else v for k, v in asdict(cfg).items()}
    settings["gamma"], settings["gae_lambda"] = cfg.discounts(flight.agent_hz)
    settings["actor_lr"] = cfg.actor_rate
    rl = {
        "algorithm": "ppo (stable-baselines3)",
        "init": str(cfg.init) if cfg.init else None,
        "steps": result.steps,
        "kept": {
            "which": cfg.keep,
            "step": result.kept_step,
            "chosen_on": result.kept.chosen_on,
            "select_success": result.kept.select_success,
        },
        "wall_s": round(result.seconds, 1),
        "envs": cfg.n_envs,
        "settings": settings,
        "curve": [asdict(p) for p in result.curve],
        "controller": asdict(result.controller),
    }
    meta = {
        **meta_of(start),
        "name": name,
        "spec": flight.to_dict(),
        "spec_note": "",
        "task": flight.task,
        "dynamic": flight.dynamic,
        "aircraft": flight.aircraft,
        "rl": rl,
    }
    try:
        with staged(result.out) as folder:
            save_policy(
                module, folder, meta, stats_of(module, "obs_norm"), stats_of(module, "action_norm")
            )
            (folder / "curve.json").write_text(json.dumps(rl, indent=1))
            title = f"{name}: {flight.task_label} on {flight.aircraft}"
            plot_curve(result.curve, result.controller, title, folder / "curve.png", result.kept)
            for part in ("tensorboard", "checkpoints"):
                if (scratch / part).is_dir():
                    shutil.copytree(scratch / part, folder / part)
    except OSError as err:
        raise ConfigError(
            f"cannot save the policy to {result.out} ({err}); free some space or give another --out"
        ) from None
