"""Configuration of a policy fine-tuned by reinforcement learning (``train ppo``): the MLP's
network, flown by the mean of the Gaussian PPO trained."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.factory import register_policy


@register_policy("ppo", "gymfg_il.policies.modeling_mlp:MLPPolicy")
@dataclass
class PPOConfig(MLPConfig):
    """An MLP fine-tuned by PPO (``python -m gymfg_il.train ppo``), made by RL rather than by
    ``train bc``: flown by its mean action, like the MLP it started from.

    Attributes:
        hidden: widths of the hidden layers (the starting MLP's).
        dropout: always 0 (PPO's likelihoods need a network without dropout).
    """

    retrains_as: ClassVar[str | None] = "mlp"

    def problems(self) -> list[str]:
        problems = super().problems()
        if self.dropout:
            problems.append(f"dropout={self.dropout!r}: a PPO policy has none")
        return problems
