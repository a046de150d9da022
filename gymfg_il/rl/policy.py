"""A cloned MLP as stable-baselines3's actor-critic, for PPO fine-tuning (``rl.model``).

The actor *is* the MLP policy (``policies.modeling_mlp``): the same network and the same
normalisation, its output the mean of PPO's Gaussian, in the MLP's normalised action units.
The env takes actions in those units (``rl.envs.normalized_actions``), so before any
update PPO's mean action is, bit for bit, the action the cloned policy flies. A policy with a
memory (``train bc --memory``) gets its observation extended by the memory from its envs
(``rl.envs.Remembering``), as it extends it itself in flight: the actor, gSDE's noise features
and the critic all see that extended observation.

Two things keep the first updates from undoing the cloning:

- the critic is warmed up first: while ``actor_frozen``, only the value network learns;
- an anchor: every optimiser step adds the gradient of ``anchor_weight`` x the mean squared
  distance between the actor's mean and the frozen starting policy's on the minibatch's
  observations (a BC term toward the start; for Gaussians of one fixed spread, their KL
  divergence up to a constant). ``rl.algorithm`` decays the weight to zero over the run.

The anchor enters through the optimiser (``AnchoredAdam``) because stable-baselines3's PPO
sums a fixed set of losses; its gradient is added after PPO's own gradient clipping.
"""

from __future__ import annotations

import copy
from typing import Any

import torch
from stable_baselines3.common.distributions import Distribution, StateDependentNoiseDistribution
from stable_baselines3.common.policies import ActorCriticPolicy
from torch import nn

from gymfg_il.policies.modeling_mlp import MLPPolicy
from gymfg_il.policies.normalize import Normalizer


class _Pass(nn.Module):
    """stable-baselines3's ``mlp_extractor`` slot, left empty: actor and critic take the
    raw observation and normalise it themselves."""

    def __init__(self, width: int) -> None:
        super().__init__()
        self.latent_dim_pi = self.latent_dim_vf = width

    def forward(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return x, x

    def forward_actor(self, x: torch.Tensor) -> torch.Tensor:
        return x

    def forward_critic(self, x: torch.Tensor) -> torch.Tensor:
        return x


class Critic(nn.Module):
    """The value network: the actor's observation normalisation (a copy, frozen), then an
    MLP of ``hidden`` widths (tanh) to one value."""

    def __init__(self, obs_norm: Normalizer, hidden: list[int]) -> None:
        super().__init__()
        self.obs_norm = copy.deepcopy(obs_norm)
        self.n_obs = int(self.obs_norm.mean.numel())
        layers: list[nn.Module] = []
        width = self.n_obs
        for h in hidden:
            layers += [nn.Linear(width, h), nn.Tanh()]
            width = h
        layers.append(nn.Linear(width, 1))
        self.net = nn.Sequential(*layers)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        out: torch.Tensor = self.net(self.obs_norm(obs))
        return out


class AnchoredAdam(torch.optim.Adam):
    """Adam whose every step first adds the gradient of the policy's anchor term
    (``AnchoredPolicy.anchor_loss``) on the minibatch the policy last evaluated, and whose
    parameter groups keep their own share (``scale``) of the learning rate stable-baselines3
    sets for all of them (a fine-tuned actor moves slower than a fresh critic learns)."""

    def __init__(self, params: Any, policy: AnchoredPolicy, **kwargs: Any) -> None:
        super().__init__(params, **kwargs)
        self._policy = [policy]  # a list: the optimiser is no submodule of the policy

    @torch.no_grad()
    def step(self, closure: Any = None) -> Any:
        with torch.enable_grad():
            loss = self._policy[0].anchor_loss()
            if loss is not None:
                loss.backward()
        for group in self.param_groups:
            if group["lr"] != group.get("applied"):  # set anew by stable-baselines3
                group["base"] = group["lr"]
            group["applied"] = group["lr"] = group["base"] * group.get("scale", 1.0)
        return super().step(closure)


class AnchoredPolicy(ActorCriticPolicy):
    """stable-baselines3's actor-critic around a cloned MLP (see the module docstring).

    ``start`` is the MLP policy module (``MLPPolicy``) the actor starts as; ``critic``
    the critic's hidden widths; ``actor_lr_scale`` the actor's share of the learning rate;
    ``log_std_init`` the log of the Gaussian's starting spread in normalised action units."""

    def __init__(
        self,
        *args: Any,
        start: MLPPolicy,
        critic: list[int] | None = None,
        actor_lr_scale: float = 1.0,
        **kwargs: Any,
    ) -> None:
        # in a list: a module cannot be an attribute before the Module's own __init__
        self._given = [start]
        self._critic_hidden = list(critic or [256, 256])
        self._actor_lr_scale = actor_lr_scale
        super().__init__(*args, **kwargs)
        self.anchor_weight = 0.0
        self._batch: torch.Tensor | None = None

    def _build(self, lr_schedule: Any) -> None:
        start = self._given[0]
        # stable-baselines3 types these slots as its own MLP and Linear layers; any module
        # with their interface fills them
        n_obs = start.n_obs
        assert self.features_dim == n_obs, (self.features_dim, n_obs)
        self.mlp_extractor = _Pass(n_obs)  # type: ignore[assignment]
        self.action_net = copy.deepcopy(start)
        self.action_net.train()
        # gSDE: the noise is a linear map of the normalised observation, drawn anew every
        # sde_sample_freq steps, so exploring moves the controls coherently for a while
        # (a white noise on the elevator at 10 Hz averages out before the altitude moves)
        if not isinstance(self.action_dist, StateDependentNoiseDistribution):
            raise TypeError("AnchoredPolicy explores with gSDE: build it with use_sde=True")
        _, self.log_std = self.action_dist.proba_distribution_net(
            latent_dim=n_obs, latent_sde_dim=n_obs, log_std_init=self.log_std_init
        )
        self.value_net = Critic(start.obs_norm, self._critic_hidden)  # type: ignore[assignment]
        # the start, frozen: a submodule, so it moves to the policy's device, and kept out
        # of the optimiser's groups
        self.anchor_net = copy.deepcopy(start).eval()
        self.anchor_net.requires_grad_(False)
        for buffer in (*self.action_net.buffers(), *self.value_net.buffers()):
            buffer.requires_grad_(False)
        actor = [*self.action_net.parameters(), self.log_std]
        left_out = {id(p) for p in (*actor, *self.anchor_net.parameters())}
        groups = [
            {"params": actor, "scale": self._actor_lr_scale},
            {"params": [p for p in self.parameters() if id(p) not in left_out], "scale": 1.0},
        ]
        self.optimizer = AnchoredAdam(
            groups, policy=self, lr=lr_schedule(1), **self.optimizer_kwargs
        )

    @property
    def actor(self) -> MLPPolicy:
        """The MLP policy module being fine-tuned (its ``forward`` is PPO's mean action)."""
        actor = self.action_net
        assert isinstance(actor, MLPPolicy)
        return actor

    def freeze_actor(self, frozen: bool) -> None:
        """While frozen, only the critic learns (the warm-up)."""
        for p in (*self.action_net.parameters(), self.log_std):
            p.requires_grad_(not frozen)

    def _get_action_dist_from_latent(self, latent_pi: torch.Tensor) -> Distribution:
        """PPO's distribution: the actor's mean; gSDE's noise features are the actor's
        normalised observation (the raw one would scale the noise by feet and knots)."""
        mean = self.action_net(latent_pi)
        assert isinstance(self.action_dist, StateDependentNoiseDistribution)
        features = self.actor.obs_norm(latent_pi)
        return self.action_dist.proba_distribution(mean, self.log_std, features)

    def evaluate_actions(
        self, obs: torch.Tensor | dict[str, torch.Tensor], actions: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]:
        assert isinstance(obs, torch.Tensor)  # a flight's observation is one vector
        self._batch = obs  # the minibatch the anchor is computed on
        return super().evaluate_actions(obs, actions)

    def anchor_loss(self) -> torch.Tensor | None:
        """``anchor_weight`` x the mean squared distance of the actor's mean action from the
        starting policy's on the last minibatch (normalised units), or None."""
        obs, self._batch = self._batch, None
        if obs is None or self.anchor_weight <= 0 or not self.log_std.requires_grad:
            return None
        with torch.no_grad():
            target = self.anchor_net(obs)
        loss: torch.Tensor = self.anchor_weight * nn.functional.mse_loss(
            self.action_net(obs), target
        )
        return loss
