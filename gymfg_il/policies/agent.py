"""A trained policy as an Agent: numpy observation in, action out, memory reset at every
episode (a policy whose configuration is ``stateful`` carries it from step to step)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.policies.normalize import OneThread


class PolicyAgent:
    """Fly a checkpoint (``load``) or a policy module in any env whose task observes the
    same variables the policy was trained on."""

    def __init__(self, policy: Any, meta: dict[str, Any], device: str = "cpu") -> None:
        import torch

        self.policy, self.meta, self.device = policy, meta, device
        self.observation_names: list[str] = list(meta["observation_names"])
        self._torch = torch
        self._state: object = None  # what the policy carries to its next step (None: fresh)
        # it carries state across steps: call it at every step, also where its action is not
        # flown (``Agent``), so the state follows the flight
        self.stateful: bool = bool(policy.config.stateful)
        # a vision policy's eyes: the env's camera of the current state (``AgentSpec.make``)
        self.camera: dict[str, Any] | None = meta.get("camera")
        self.see: Callable[[], np.ndarray] | None = None

    @classmethod
    def load(cls, path: Path, device: str = "cpu") -> PolicyAgent:
        from gymfg_il.policies.checkpoint import load_policy

        policy, meta = load_policy(path, device)
        return cls(policy, meta, device)

    @property
    def name(self) -> str:
        return str(self.meta.get("name", self.meta.get("type", "policy")))

    def check_observation(self, names: Sequence[str]) -> None:
        if list(names) != self.observation_names:
            raise ConfigError(
                f"the policy observes {self.observation_names} but this env gives "
                f"{list(names)}; fly it on the task it was trained on "
                f"({self.meta.get('task')} on {self.meta.get('aircraft')})"
            )

    def reset(self, seed: int | None = None) -> None:
        self._state = None

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        if self.camera is None:  # the raw action: the rollout loop (or the env) clips it
            action, self._state = self.policy.step(observation, self._state)
            return action
        if self.see is None:
            raise ConfigError(
                f"{self.name} flies by its camera ({self.camera['view']}): fly it in a "
                "GymFG env (eval, collect dagger), which gives it the camera's frames"
            )
        torch = self._torch
        obs = torch.as_tensor(np.asarray(observation, dtype=np.float32), device=self.device)
        frame = torch.as_tensor(self.see(), device=self.device)
        with OneThread():
            inputs = (frame.unsqueeze(0), obs.unsqueeze(0))
            action, self._state = self.policy.act(inputs, self._state)
        out: np.ndarray = action[0].double().cpu().numpy()
        return out
