"""Mean/std normalisation from a dataset's statistics, kept as module buffers so it travels
inside the checkpoint."""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn


class OneThread:
    """Torch on one thread while a step of flight runs (the setting as it was after it).

    A step's layers are far too small to share between threads, and torch's exact GELU opens
    a parallel region even for 256 values: with two threads on a busy 2-core machine a GELU
    took 1.4 ms on average and 16 ms at the 99th percentile, against 13 µs on one thread, so
    an eval flown in its own process (``--workers 1``) or a 30 Hz session with an assistant
    waited on it (the worker processes already run one thread each). A class, not a
    generator: ``contextlib.contextmanager`` cost 6 µs a step."""

    __slots__ = ("threads",)

    def __enter__(self) -> None:
        self.threads = torch.get_num_threads()
        if self.threads != 1:
            torch.set_num_threads(1)

    def __exit__(self, *exc: object) -> None:
        if self.threads != 1:
            torch.set_num_threads(self.threads)


class Normalizer(nn.Module):
    mean: torch.Tensor
    std: torch.Tensor

    def __init__(self, mean: np.ndarray, std: np.ndarray, eps: float = 1e-6) -> None:
        super().__init__()
        std = np.where(np.asarray(std) < eps, 1.0, std)  # constant features pass through
        self.register_buffer("mean", torch.as_tensor(np.asarray(mean), dtype=torch.float32))
        self.register_buffer("std", torch.as_tensor(np.asarray(std), dtype=torch.float32))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return (x - self.mean) / self.std

    def inverse(self, x: torch.Tensor) -> torch.Tensor:
        return x * self.std + self.mean


class NormalizedPolicy(nn.Module):
    """What every policy shares: its config and the observation and action normalisers, so
    the checkpoint carries the dataset's statistics. Subclasses build the network on
    ``self.n_obs`` inputs and ``self.n_act`` (normalised) outputs, and define
    ``loss(inputs, action)`` for a batch of their ``Window`` (``learning.batches``) and
    ``act(inputs, state) -> (action, state)`` for one step of flight (``policies.agent``)."""

    loss_label = "MSE (normalised actions)"  # what ``loss`` is, for the loss curve

    def __init__(
        self, config: object, obs_stats: dict[str, np.ndarray], action_stats: dict[str, np.ndarray]
    ) -> None:
        super().__init__()
        self.config = config
        self.obs_norm = Normalizer(obs_stats["mean"], obs_stats["std"])
        self.action_norm = Normalizer(action_stats["mean"], action_stats["std"])
        self.n_obs, self.n_act = len(obs_stats["mean"]), len(action_stats["mean"])
        self.obs_noise = 0.0  # training only: std of noise on the normalised observation

    def act(self, inputs: Any, state: Any = None) -> tuple[torch.Tensor, Any]:
        """The raw actions for a batch of inputs, and the state carried on (each subclass's)."""
        raise NotImplementedError

    def step(self, observation: np.ndarray, state: Any = None) -> tuple[np.ndarray, Any]:
        """One step of flight from one raw observation (``act`` on a batch of one), on one
        torch thread (``OneThread``): the raw action (float64) and the state carried to the
        next step (``policies.agent``)."""
        device = self.obs_norm.mean.device
        obs = torch.as_tensor(np.asarray(observation, dtype=np.float32), device=device)
        with OneThread():
            action, state = self.act(obs.unsqueeze(0), state)
        out: np.ndarray = action[0].double().cpu().numpy()
        return out, state

    def normalized(self, obs: torch.Tensor) -> torch.Tensor:
        """The normalised observation; while training, with ``obs_noise`` added (the policy
        learns to act alike in a neighbourhood of each demonstrated state)."""
        x = self.obs_norm(obs)
        if self.training and self.obs_noise:
            x = x + self.obs_noise * torch.randn_like(x)
        return x
