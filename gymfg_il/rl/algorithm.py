"""The algorithm: stable-baselines3's PPO, and only what fine-tuning a cloned actor changes
in it (``FineTunePPO.train``): the actor held while the critic warms up, its learning rate
ramped up after, and the anchor's weight set before every update. Sampling is PPO's own
(``collect_rollouts``), or the grouped sampler's (``rl.grouped.GroupedPPO``)."""

from __future__ import annotations

from stable_baselines3 import PPO

from gymfg_il.rl.policy import AnchoredPolicy


class FineTunePPO(PPO):
    """stable-baselines3's PPO, holding the actor while the critic warms up (the first
    ``warmup`` env steps), then ramping the actor's learning rate up from 0 over ``ramp``
    env steps (Adam's first steps, with no history of the gradient, move every weight by
    about the full rate: a cloned network is knocked off its solution), and setting the
    anchor's weight before every update: ``anchor``, decaying linearly to 0 over ``span``
    env steps after the warm-up; the actor learns at ``actor_scale`` x the critic's rate."""

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
