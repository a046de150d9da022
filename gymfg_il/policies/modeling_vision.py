"""The vision policy: an eye (a CNN over stacked camera frames that estimates the aircraft's
state the task observes) and hands (an MLP that flies from those estimates and the task's
targets and instruments). Trained together by behaviour cloning; in flight the agent hands
it the env's camera frame beside the observation (``policies.agent``), of which it reads
only the targets and what is given (``VisionConfig``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_vision import ROLL_INVARIANT, VisionConfig
from gymfg_il.policies.normalize import NormalizedPolicy
from gymfg_il.policies.window import pool_frames
from gymfg_il.units import DEG_TO_RAD, wrap_180


class VisionPolicy(NormalizedPolicy):
    seen_index: torch.Tensor
    target_index: torch.Tensor
    error_index: torch.Tensor
    error_seen: torch.Tensor
    error_target: torch.Tensor
    integral_index: torch.Tensor
    integral_error: torch.Tensor
    integral_limit: torch.Tensor
    hands_index: torch.Tensor
    eye_error: torch.Tensor
    kept_when_rolled: torch.Tensor

    def __init__(
        self,
        config: VisionConfig,
        obs_stats: dict[str, np.ndarray],
        action_stats: dict[str, np.ndarray],
    ) -> None:
        super().__init__(config, obs_stats, action_stats)
        self.config: VisionConfig = config
        self.loss_label = f"action MSE + {config.aux_weight:g} x eye MSE (normalised)"
        layers: list[nn.Module] = []
        width = 3 * config.frames
        for c in config.channels:
            layers += [nn.Conv2d(width, c, 3, stride=2, padding=1), nn.GELU()]
            width = c
        side = config.image_size // config.pool // 2 ** len(config.channels)
        n_seen = len(config.seen_index)
        self.eye = nn.Sequential(
            *layers,
            nn.Flatten(),
            nn.Linear(width * side * side, 256),
            nn.GELU(),
            nn.Linear(256, n_seen),
        )
        indices = ["seen_index", "target_index", "error_index", "error_seen", "error_target"]
        for name in [*indices, "integral_index", "integral_error"]:
            self.register_buffer(name, torch.as_tensor(getattr(config, name), dtype=torch.long))
        limit = [v if v > 0 else math.inf for v in config.integral_limit]
        self.register_buffer("integral_limit", torch.as_tensor(limit, dtype=torch.float32))
        hands = [*config.seen_index, *config.target_index, *config.error_index]
        hands += config.integral_index + config.given_index
        self.register_buffer("hands_index", torch.as_tensor(hands, dtype=torch.long))
        # the eye's running RMS error on the training frames (normalised), per seen entry
        self.register_buffer("eye_error", torch.zeros(n_seen))
        seen = config.seen_names
        self.roll_at = seen.index("roll_deg") if "roll_deg" in seen else -1
        kept = [n in ROLL_INVARIANT or n == "roll_deg" for n in seen]
        self.register_buffer("kept_when_rolled", torch.as_tensor(kept, dtype=torch.bool))
        mlp: list[nn.Module] = []
        width = len(hands)
        for h in config.hidden:
            mlp += [nn.Linear(width, h), nn.GELU()]
            width = h
        mlp.append(nn.Linear(width, self.n_act))
        self.hands = nn.Sequential(*mlp)

    # -- the eye ---------------------------------------------------------------------------
    def look(self, images: torch.Tensor) -> torch.Tensor:
        """Normalised estimates of ``seen_names`` from pooled frames (batch, frames, H, W, 3)
        uint8 (``pool_frames``)."""
        b, f, h, w, _ = images.shape
        x = images.permute(0, 1, 4, 2, 3).reshape(b, f * 3, h, w).float() / 255.0 - 0.5
        return self.eye(x)

    def _seen_raw(self, estimate: torch.Tensor) -> torch.Tensor:
        return estimate * self.obs_norm.std[self.seen_index] + self.obs_norm.mean[self.seen_index]

    def _errors(self, obs: torch.Tensor, seen: torch.Tensor) -> torch.Tensor:
        """Raw errors to the targets from raw seen values, as the task computes them (none
        wraps: the heading is an instrument, ``configuration_vision.INSTRUMENTS``)."""
        targets = obs[:, self.target_index]
        return targets[:, self.error_target] - seen[:, self.error_seen]

    # -- the hands -------------------------------------------------------------------------
    def fly(self, obs: torch.Tensor) -> torch.Tensor:
        """Normalised action from a raw observation (of which the hands read the seen
        entries, the targets, the errors and their integrals, and what is given)."""
        return self.hands(self.obs_norm(obs)[:, self.hands_index])

    def forward(self, images: torch.Tensor, obs: torch.Tensor) -> torch.Tensor:
        """Normalised action from frames and an observation whose seen entries and errors
        are replaced by the eye's estimates (its integrals are the observation's)."""
        obs = obs.clone()
        seen = self._seen_raw(self.look(images))
        obs[:, self.seen_index] = seen
        obs[:, self.error_index] = self._errors(obs, seen)
        return self.fly(obs)

    def loss(self, inputs: tuple[torch.Tensor, torch.Tensor], action: torch.Tensor) -> torch.Tensor:
        """The eye's error on the seen entries (weighted ``aux_weight``) plus the hands' on the
        action, flown from the demonstrated state with the eye's running error added to what
        it estimates (and carried into the errors, as it would be in flight)."""
        images, obs = inputs
        truth_raw = obs[:, self.seen_index]
        weight = torch.ones_like(truth_raw)
        if self.training:
            images, truth_raw, weight = self._rolled(images, truth_raw, weight)
        estimate = self.look(images)
        truth = (truth_raw - self.obs_norm.mean[self.seen_index]) / self.obs_norm.std[
            self.seen_index
        ]
        squared = (estimate - truth).pow(2) * weight
        eye_loss = squared.sum() / weight.sum()
        if self.training:
            with torch.no_grad():
                rms = (squared.sum(dim=0) / weight.sum(dim=0).clamp_min(1.0)).sqrt()
                fresh = bool((self.eye_error == 0).all())
                self.eye_error.copy_(rms if fresh else 0.98 * self.eye_error + 0.02 * rms)
        noisy = obs.clone()
        if self.config.noise_scale and self.training:
            std = self.eye_error * self.obs_norm.std[self.seen_index] * self.config.noise_scale
            seen = obs[:, self.seen_index] + torch.randn_like(std.expand_as(truth_raw)) * std
            noisy[:, self.seen_index] = seen
            noisy[:, self.error_index] = self._errors(obs, seen)
        predicted = self.fly(noisy)
        act_loss = nn.functional.mse_loss(predicted, self.action_norm(action))
        return act_loss + self.config.aux_weight * eye_loss

    def _rolled(
        self, images: torch.Tensor, truth: torch.Tensor, weight: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """``augment_share`` of the frame stacks rotated about the image centre by up to
        ``roll_augment_deg``, with their roll label moved by the same angle (the front
        camera's optical axis is the roll axis) and the entries a roll changes otherwise
        weighted 0."""
        cfg = self.config
        if not cfg.roll_augment_deg or self.roll_at < 0 or cfg.camera != "front":
            return images, truth, weight
        b, f, h, w, _ = images.shape
        chosen = torch.rand(b, device=images.device) < cfg.augment_share
        if not bool(chosen.any()):
            return images, truth, weight
        n = int(chosen.sum())
        angle = (torch.rand(n, device=images.device) * 2 - 1) * cfg.roll_augment_deg
        a = angle * DEG_TO_RAD
        cos, sin, zero = torch.cos(a), torch.sin(a), torch.zeros_like(a)
        theta = torch.stack(
            [torch.stack([cos, -sin, zero], 1), torch.stack([sin, cos, zero], 1)], 1
        )
        x = images[chosen].permute(0, 1, 4, 2, 3).reshape(n, f * 3, h, w).float()
        grid = nn.functional.affine_grid(theta, list(x.shape), align_corners=False)
        x = nn.functional.grid_sample(x, grid, padding_mode="border", align_corners=False)
        x = x.round().clamp(0, 255).reshape(n, f, 3, h, w).permute(0, 1, 3, 4, 2)
        images = images.float().clone()
        images[chosen] = x
        truth, weight = truth.clone(), weight.clone()
        roll = truth[chosen, self.roll_at] + angle
        truth[chosen, self.roll_at] = wrap_180(roll)
        weight[chosen] = self.kept_when_rolled.to(weight.dtype)
        return images, truth, weight

    @torch.no_grad()
    def act(
        self, inputs: tuple[torch.Tensor, torch.Tensor], state: Any = None
    ) -> tuple[torch.Tensor, Any]:
        """Raw action for one step: (frame (batch, H, W, 3) uint8, observation (batch, n_obs));
        ``state`` keeps the (pooled) frames before and the integrals of the errors the policy
        estimated (None at an episode's start)."""
        frame, obs = inputs
        frame = pool_frames(frame, self.config.pool).unsqueeze(1)
        if state is None:
            stack = frame.repeat(1, self.config.frames, 1, 1, 1)
            integrals = torch.zeros(len(obs), len(self.integral_index), device=obs.device)
        else:
            stack, integrals = state
            stack = torch.cat([stack[:, 1:], frame], dim=1)
        obs = obs.clone()
        seen = self._seen_raw(self.look(stack))
        errors = self._errors(obs, seen)
        # the integrals count the current step's error and saturate, as the task's do
        integrals = integrals + errors[:, self.integral_error] * self.config.dt
        integrals = torch.maximum(
            torch.minimum(integrals, self.integral_limit), -self.integral_limit
        )
        obs[:, self.seen_index] = seen
        obs[:, self.error_index] = errors
        obs[:, self.integral_index] = integrals
        return self.action_norm.inverse(self.fly(obs)), (stack, integrals)
