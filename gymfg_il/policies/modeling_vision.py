"""The vision policy: a CNN encoder over stacked camera frames, joined with the task's
targets, then an MLP to the action. Trained by behaviour cloning like the others; in flight
the agent hands it the env's camera frame beside the observation (``policies.agent``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_vision import VisionConfig
from gymfg_il.policies.normalize import NormalizedPolicy


class VisionPolicy(NormalizedPolicy):
    index: torch.Tensor
    aux_index: torch.Tensor
    memory_index: torch.Tensor
    memory_source: torch.Tensor
    recurrent = False
    needs_camera = True

    def __init__(
        self,
        config: VisionConfig,
        obs_stats: dict[str, np.ndarray],
        action_stats: dict[str, np.ndarray],
    ) -> None:
        super().__init__(config, obs_stats, action_stats)
        self.config: VisionConfig = config
        layers: list[nn.Module] = []
        width = 3 * config.frames
        for c in config.channels:
            layers += [nn.Conv2d(width, c, 3, stride=2, padding=1), nn.GELU()]
            width = c
        side = config.image_size // config.pool // 2 ** len(config.channels)
        self.encoder = nn.Sequential(*layers, nn.Flatten(), nn.Linear(width * side * side, 256))
        self.register_buffer("index", torch.as_tensor(config.state_index, dtype=torch.long))
        self.register_buffer("aux_index", torch.as_tensor(config.aux_index, dtype=torch.long))
        for name in ("memory_index", "memory_source"):
            self.register_buffer(name, torch.as_tensor(getattr(config, name), dtype=torch.long))
        n_aux = len(config.aux_index)
        self.estimate = nn.Sequential(nn.Linear(256, 256), nn.GELU(), nn.Linear(256, n_aux))
        mlp: list[nn.Module] = []
        width = 256 + n_aux + len(config.state_index) + len(config.memory_index)
        for h in config.hidden:
            mlp += [nn.Linear(width, h), nn.GELU()]
            width = h
        mlp.append(nn.Linear(width, self.n_act))
        self.head = nn.Sequential(*mlp)

    def forward(self, images: torch.Tensor, obs: torch.Tensor) -> torch.Tensor:
        """Normalised action from pooled frames (batch, frames, H / pool, W / pool, 3) uint8
        (``pool_frames``) and raw observations (batch, n_obs), of which the policy reads
        ``state_index``."""
        return self._forward(images, obs)[0]

    def _forward(
        self, images: torch.Tensor, obs: torch.Tensor, memory: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """(normalised action, the estimate of the normalised ``aux_index`` entries); the
        error integrals are ``memory`` (raw) when given, else the observation's."""
        b, f, h, w, _ = images.shape
        x = images.permute(0, 1, 4, 2, 3).reshape(b, f * 3, h, w).float() / 255.0 - 0.5
        if memory is not None:
            obs = obs.clone()
            obs[:, self.memory_index] = memory
        normal = self.normalized(obs)
        features = nn.functional.gelu(self.encoder(x))
        estimate = self.estimate(features)
        inputs = [features, estimate, normal[:, self.index], normal[:, self.memory_index]]
        return self.head(torch.cat(inputs, dim=1)), estimate

    def loss(self, inputs: tuple[torch.Tensor, torch.Tensor], action: torch.Tensor) -> torch.Tensor:
        """The action's error plus ``aux_weight`` times the estimate's (both normalised)."""
        images, obs = inputs
        predicted, estimate = self._forward(images, obs)
        loss = nn.functional.mse_loss(predicted, self.action_norm(action))
        if self.config.aux_weight and len(self.config.aux_index):
            truth = self.obs_norm(obs)[:, self.aux_index]
            loss = loss + self.config.aux_weight * nn.functional.mse_loss(estimate, truth)
        return loss

    @torch.no_grad()
    def act(
        self, inputs: tuple[torch.Tensor, torch.Tensor], state: Any = None
    ) -> tuple[torch.Tensor, Any]:
        """Raw action for one step: (frame (batch, H, W, 3) uint8, observation (batch, n_obs));
        ``state`` keeps the (pooled) frames before and the error integrals of the policy's own
        estimates (None at an episode's start)."""
        frame, obs = inputs
        frame = pool_frames(frame, self.config.pool).unsqueeze(1)
        if state is None:
            stack = frame.repeat(1, self.config.frames, 1, 1, 1)
            memory = torch.zeros(len(obs), len(self.config.memory_index), device=obs.device)
        else:
            stack, memory = state
            stack = torch.cat([stack[:, 1:], frame], dim=1)
        # the integrals count the current step's error, as the task's do: estimate it first
        _, estimate = self._forward(stack, obs, memory)
        index = self.aux_index[self.memory_source]
        error = (
            estimate[:, self.memory_source] * self.obs_norm.std[index] + self.obs_norm.mean[index]
        )
        memory = memory + error * self.config.dt
        action, _ = self._forward(stack, obs, memory)
        return self.action_norm.inverse(action), (stack, memory)


def pool_frames(frames: torch.Tensor, pool: int) -> torch.Tensor:
    """Frames (..., H, W, 3) uint8 averaged over ``pool`` x ``pool`` blocks and rounded back to
    uint8: done once to a dataset's frames before training, and to every frame in flight, so
    both see the same pixels (and training gathers 1 / pool^2 of the bytes)."""
    if pool == 1:
        return frames
    *lead, h, w, c = frames.shape
    blocks = frames.reshape(*lead, h // pool, pool, w // pool, pool, c).float()
    return blocks.mean(dim=(-4, -2)).round().to(torch.uint8)
