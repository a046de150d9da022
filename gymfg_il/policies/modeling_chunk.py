"""The chunking policy: an MLP from the last ``history`` observations to the next ``chunk``
actions; in flight every step predicts a chunk and the action flown averages the overlapping
predictions (temporal ensembling), which smooths the policy's errors instead of compounding
them step by step."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_chunk import ChunkConfig
from gymfg_il.policies.normalize import NormalizedPolicy


class ChunkPolicy(NormalizedPolicy):
    def __init__(
        self,
        config: ChunkConfig,
        obs_stats: dict[str, np.ndarray],
        action_stats: dict[str, np.ndarray],
    ) -> None:
        super().__init__(config, obs_stats, action_stats)
        self.config: ChunkConfig = config
        layers: list[nn.Module] = []
        width = self.n_obs * config.history
        for h in config.hidden:
            layers += [nn.Linear(width, h), nn.GELU()]
            width = h
        layers.append(nn.Linear(width, self.n_act * config.chunk))
        self.net = nn.Sequential(*layers)

    def forward(self, history: torch.Tensor) -> torch.Tensor:
        """Normalised chunks (batch, chunk, n_act) from raw histories (batch, history, n_obs)."""
        x = self.normalized(history).flatten(1)
        return self.net(x).view(len(history), self.config.chunk, self.n_act)

    def loss(self, history: torch.Tensor, chunk: torch.Tensor) -> torch.Tensor:
        """MSE over the chunk's actions that lie inside the episode (NaN marks the rest)."""
        valid = ~torch.isnan(chunk)
        target = self.action_norm(torch.nan_to_num(chunk))
        err = (self.forward(history) - target) ** 2
        return (err * valid).sum() / valid.sum().clamp(min=1)

    @torch.no_grad()
    def act(self, obs: torch.Tensor, state: Any = None) -> tuple[torch.Tensor, Any]:
        """Raw action for (batch, n_obs) observations; ``state`` carries the history and the
        chunks still being flown (None at an episode's start)."""
        cfg = self.config
        if state is None:
            history = obs.unsqueeze(1).repeat(1, cfg.history, 1)
            chunks: list[torch.Tensor] = []
        else:
            history, chunks = state
            history = torch.cat([history[:, 1:], obs.unsqueeze(1)], dim=1)
        chunks = (
            [*chunks[-(cfg.chunk - 1) :], self.forward(history)]
            if cfg.chunk > 1
            else [self.forward(history)]
        )
        # chunk j (oldest first) was made len - 1 - j steps ago: its entry for now is that one
        n = len(chunks)
        preds = torch.stack([c[:, n - 1 - j] for j, c in enumerate(chunks)], dim=0)
        weights = torch.tensor(
            [math.exp(-cfg.ensemble_decay * (n - 1 - j)) for j in range(n)], dtype=preds.dtype
        ).to(preds.device)
        action = (preds * weights[:, None, None]).sum(0) / weights.sum()
        return self.action_norm.inverse(action), (history, chunks)
