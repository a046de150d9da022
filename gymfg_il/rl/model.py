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
    ppo, (gamma, gae_lambda) = cfg.ppo, cfg.discounts(agent_hz)
    algorithm = GroupedPPO if cfg.sampler == "grouped" else FineTunePPO
    # gSDE's noise on one control sums one term per observed variable (each of about unit
    # spread, normalised): its spread is about sqrt(n) x the matrix's
    sde_features = module.n_obs
    model = algorithm(
        AnchoredPolicy,
        venv,
        learning_rate=ppo.lr,
        n_steps=ppo.rollout_steps,
        batch_size=ppo.batch_size,
        n_epochs=ppo.epochs,
        gamma=gamma,
        gae_lambda=gae_lambda,
        clip_range=ppo.clip_range,
        target_kl=ppo.target_kl or None,
        ent_coef=0.0,
        use_sde=True,
        sde_sample_freq=-1,  # a new noise map per rollout
        policy_kwargs={
            "start": module,
            "critic": list(ppo.critic),
            "actor_lr_scale": cfg.actor_rate / ppo.lr,
            "log_std_init": math.log(ppo.action_std / math.sqrt(sde_features)),
            "ortho_init": False,
        },
        tensorboard_log=str(tensorboard),
        seed=cfg.seed,
        device=device,
        verbose=0,
    )
    model.warmup, model.span = cfg.warmup_steps, cfg.anchor_span
    model.ramp = cfg.warmup_steps if cfg.init is not None else 0
    model.actor_scale = cfg.actor_rate / ppo.lr
    model.anchor = ppo.anchor if cfg.init is not None else 0.0  # from scratch, nothing to keep
    return model
