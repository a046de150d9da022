"""The GRU policy: a recurrent memory over the normalised observations."""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.normalize import NormalizedPolicy


class GRUPolicy(NormalizedPolicy):
    def __init__(
        self,
        config: GRUConfig,
        obs_stats: dict[str, np.ndarray],
        action_stats: dict[str, np.ndarray],
    ) -> None:
        super().__init__(config, obs_stats, action_stats)
        self.config: GRUConfig = config
        n_obs, n_act = self.n_obs, self.n_act
        self.encoder = nn.Sequential(nn.Linear(n_obs, config.hidden), nn.GELU())
        self.gru = nn.GRU(config.hidden, config.hidden, config.layers, batch_first=True)
        self.head = nn.Linear(config.hidden, n_act)

    def forward(
        self, obs: torch.Tensor, state: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """(normalised actions, state) for raw observations of shape (batch, time, n_obs)."""
        out, state = self.gru(self.encoder(self.normalized(obs)), state)
        return self.head(out), state

    def loss(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        pred, _ = self.forward(obs)
        return nn.functional.mse_loss(pred, self.action_norm(action))

    @torch.no_grad()
    def act(self, obs: torch.Tensor, state: object = None) -> tuple[torch.Tensor, object]:
        """Raw action for (batch, n_obs) observations, carrying the GRU state."""
        pred, new_state = self.forward(obs.unsqueeze(1), state)  # type: ignore[arg-type]
        return self.action_norm.inverse(pred[:, 0]), new_state
