"""The MLP policy: normalised observation in, normalised action out."""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.normalize import NormalizedPolicy


class MLPPolicy(NormalizedPolicy):
    def __init__(
        self,
        config: MLPConfig,
        obs_stats: dict[str, np.ndarray],
        action_stats: dict[str, np.ndarray],
    ) -> None:
        super().__init__(config, obs_stats, action_stats)
        self.config: MLPConfig = config
        n_obs, n_act = self.n_obs, self.n_act
        layers: list[nn.Module] = []
        width = n_obs
        for h in config.hidden:
            layers += [nn.Linear(width, h), nn.GELU()]
            if config.dropout:
                layers.append(nn.Dropout(config.dropout))
            width = h
        layers.append(nn.Linear(width, n_act))
        self.net = nn.Sequential(*layers)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """Normalised action predicted from raw observations (any leading dims)."""
        return self.net(self.normalized(obs))

    def loss(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return nn.functional.mse_loss(self.forward(obs), self.action_norm(action))

    @torch.no_grad()
    def act(self, obs: torch.Tensor, state: object = None) -> tuple[torch.Tensor, object]:
        """Raw action for a batch of raw observations; no memory."""
        return self.action_norm.inverse(self.forward(obs)), None
