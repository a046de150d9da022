"""The PPO model of a run (``make_model``): the algorithm for the chosen sampler
(``rl.algorithm.FineTunePPO``, or ``rl.grouped.GroupedPPO``) around the actor-critic built
from the starting MLP (``rl.policy.AnchoredPolicy``), with the run's settings."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from gymfg_il.rl.algorithm import FineTunePPO
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.rl.grouped.algorithm import GroupedPPO
from gymfg_il.rl.policy import AnchoredPolicy


def make_model(
    cfg: PPORunConfig, venv: Any, module: Any, tensorboard: Path, device: str, agent_hz: int
) -> FineTunePPO:
    """stable-baselines3's PPO with the cloned actor ``module``, the critic warm-up and the
    anchor, on ``venv``, for a flight at ``agent_hz`` (the discount's rate)."""
    gamma, gae_lambda = cfg.discounts(agent_hz)
    algorithm = GroupedPPO if cfg.sampler == "grouped" else FineTunePPO
    # gSDE's noise on one control sums one term per observed variable (each of about unit
    # spread, normalised): its spread is about sqrt(n) x the matrix's
    sde_features = module.n_obs
    model = algorithm(
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
