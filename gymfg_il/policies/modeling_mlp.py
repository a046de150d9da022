"""The MLP policy: normalised observation in, normalised action out; with ``memory``, the
observation extended by its loop integrals (``policies.memory``), carried as its state."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
import torch
from torch import nn

from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.normalize import NormalizedPolicy, OneThread

# how firmly training holds the memory's layer at the expert's integral terms: a squared
# distance of 100 (normalised units; the terms are 10-80) costs what a mean squared action
# error of 1 does
MEMORY_PULL = 0.01


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
        # with memory, its columns (the last) reach the action through a linear layer alone,
        # as a PID's integral term does: beyond the integrals the demonstrations showed (a
        # gust), the clone answers as the loops it learned from, where an MLP's answer is
        # anyone's guess (still-air clones crashed 5 of 8 in turbulence that way)
        self.n_memory = len(config.memory_names)
        self.integral = nn.Linear(self.n_memory, n_act, bias=False) if self.n_memory else None
        layers: list[nn.Module] = []
        width = n_obs - self.n_memory
        for h in config.hidden:
            layers += [nn.Linear(width, h), nn.GELU()]
            if config.dropout:
                layers.append(nn.Dropout(config.dropout))
            width = h
        layers.append(nn.Linear(width, n_act))
        self.net = nn.Sequential(*layers)
        self._recipe: Any = None  # what makes the memory of a new episode, built once
        self._anchor: tuple[torch.Tensor, float] | None = None  # the memory's prior, training

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """Normalised action predicted from raw observations (any leading dims); with
        ``memory``, observations already extended by the memory's columns."""
        return self._head(self.normalized(obs))

    def _head(self, x: torch.Tensor) -> torch.Tensor:
        """The normalised action from normalised observations ``x``: the network, and with
        memory its columns (the last) through the linear layer alone."""
        if self.integral is None:
            return self.net(x)
        k = self.n_memory
        return self.net(x[..., :-k]) + self.integral(x[..., -k:])

    def loss(self, obs: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        loss = nn.functional.mse_loss(self.forward(obs), self.action_norm(action))
        if self._anchor is not None and self.training and self.integral is not None:
            prior, pull = self._anchor
            weight = self.integral.weight  # the prior follows the policy to its device
            loss = loss + pull * (weight - prior.to(weight.device)).square().sum()
        return loss

    def anchor_memory(self, pull: float = MEMORY_PULL) -> None:
        """Start the memory's layer at the expert's integral terms (``LoopMemory.
        expert_gains`` in this policy's normalised units) and, while training, hold it there
        with ``pull`` times the squared distance (in the runs measured it moved by less than
        0.1 %): an integral the demonstrations barely moved (a loop that only holds its
        start value in still air) then answers a gust as the expert's loop would, and what
        the data says beyond those terms is the network's to learn. Where the observation
        also sums a remembered loop's error, the network does not read that entry (below).
        Only ``train bc`` holds it so: ``train ppo`` fine-tunes every weight."""
        if self.integral is None or self.n_act != 4:
            return
        memory = self.recipe().new(self.config.memory)
        gains = memory.expert_gains()
        # in this policy's own units: each integral as its normaliser reads it, per action std
        memory_std = self.obs_norm.std.detach().cpu().numpy()[-self.n_memory :]
        action_std = self.action_norm.std.detach().cpu().numpy().reshape(-1, 1)
        weight = self.integral.weight
        prior = torch.as_tensor(
            gains * memory_std[None, :] / action_std, dtype=weight.dtype, device=weight.device
        )
        with torch.no_grad():
            weight.copy_(prior)
        self._anchor = (prior, pull)
        # a remembered loop whose error the observation also sums (the approach's airspeed,
        # its own sum, which winds up where the loop's anti-windup stops): the network does
        # not read that sum, its first layer's column held at zero, so the integral reaches
        # the action through the expert's term alone. Reading both, the network learned to
        # more than cancel the term through the task's sum: the f15's clones flew the
        # approach 57-65 kt fast, the throttle rising as the speed grew; without the term,
        # gusts undid the c172p's approach
        copies = [i for loop, i in memory.pilot.observed_integrals.items() if loop in memory.loops]
        if copies:
            first = self.net[0]
            assert isinstance(first, nn.Linear)
            keep = torch.ones_like(first.weight)
            keep[:, copies] = 0.0
            with torch.no_grad():
                first.weight.mul_(keep)
            first.weight.register_hook(lambda grad: grad * keep.to(grad.device))

    @torch.no_grad()
    def act(self, obs: torch.Tensor, state: Any = None) -> tuple[torch.Tensor, Any]:
        """Raw action for a batch of raw observations; with ``memory``, ``state`` is each
        row's memory (None at an episode's start)."""
        if self.n_memory:
            obs, state = self.remember(obs, state)
        return self.action_norm.inverse(self.forward(obs)), state

    def step(self, observation: np.ndarray, state: Any = None) -> tuple[np.ndarray, Any]:
        """``NormalizedPolicy.step`` with the elementwise arithmetic (normalising, the memory,
        the action's scale) in numpy and only the layers in torch (on one thread,
        ``OneThread``), on the CPU in eval mode:
        float32 operations rounded as torch's are, so the same action bit for bit, at about
        two thirds of the cost of a step (eval, PPO's evaluations and DAgger fly it at every
        step: tests/policies/test_agent.py)."""
        obs_mean = self.obs_norm.mean
        if self.training or obs_mean.device.type != "cpu":
            return super().step(observation, state)
        obs = np.asarray(observation, dtype=np.float32)
        if self.n_memory:
            state = state if state is not None else self._fresh_memories(1)
            obs = np.concatenate([obs, state[0](obs)])
        x = torch.from_numpy((obs - obs_mean.numpy()) / self.obs_norm.std.numpy())[None]
        with torch.no_grad(), OneThread():
            y = self._head(x)
        norm = self.action_norm
        out: np.ndarray = (y.numpy()[0] * norm.std.numpy() + norm.mean.numpy()).astype(np.float64)
        return out, state

    def remember(self, obs: torch.Tensor, state: Any) -> tuple[torch.Tensor, Any]:
        """The observations extended by their memory, and the memory carried on."""
        if state is None:
            state = self._fresh_memories(len(obs))
        rows = obs.detach().cpu().numpy()
        memory = np.stack([m(row) for m, row in zip(state, rows, strict=True)])
        return torch.cat([obs, torch.as_tensor(memory, device=obs.device)], dim=-1), state

    def _fresh_memories(self, n: int) -> list[Any]:
        """A new memory for each of ``n`` rows: an episode's start."""
        fresh = self.memory_maker()
        assert fresh is not None, "called with memory only"
        return [fresh() for _ in range(n)]

    def memory_maker(self) -> Callable[[], Any] | None:
        """What makes the fresh memory of an episode (a ``LoopMemory``), or None without
        memory: picklable, so an env in another process (PPO's, ``rl.envs.Remembering``)
        computes the memory with the code and the numbers this policy flies with."""
        if not self.n_memory:
            return None
        return partial(self.recipe().new, self.config.memory)

    def recipe(self) -> Any:
        if self._recipe is None:
            from gymfg_il.policies.memory import LoopMemoryRecipe

            cfg = self.config
            assert cfg.memory_flight is not None, "for_data fills in the memory's flight"
            self._recipe = LoopMemoryRecipe.for_flight(cfg.memory_flight, cfg.memory_observation)
        return self._recipe
