"""The one interface every pilot implements: a human, a PID controller, a learned policy.

Any Agent can fly any aircraft in any environment, and be recorded or evaluated the same way.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Agent(Protocol):
    """Chooses ``[aileron, elevator, rudder, throttle]`` from the task's observation.

    ``reset`` is called at the start of each episode with a seed derived from the
    environment's, so a stochastic agent is reproducible too. ``opponent_states`` holds what
    the aircraft may see of other teams (one row per aircraft), or is empty. An agent may also
    have ``start_from(action)``: the rollout calls it after ``reset`` with the controls the
    aircraft starts with (a trimmed start's throttle), so controllers start from the trim.
    An agent whose ``stateful`` attribute is True carries state from step to step (a
    recurrent policy's memory): it is reset at every episode's start and must be called at
    every step, also where its action is not flown (a person's takeover), so that the state
    follows the flight.
    """

    def reset(self, seed: int | None = None) -> None: ...

    def act(
        self, observation: np.ndarray, opponent_states: np.ndarray | None = None
    ) -> np.ndarray: ...


class ConstantAgent:
    """Always the same action (handy as a baseline and for tests)."""

    def __init__(self, action: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.7)):
        self.action = np.asarray(action, dtype=np.float64)

    def reset(self, seed: int | None = None) -> None:
        pass

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        return self.action.copy()


class RandomAgent:
    """Uniformly random surfaces around a fixed throttle, seeded at every reset."""

    def __init__(self, scale: float = 0.3, throttle: float = 0.7) -> None:
        self.scale, self.throttle = scale, throttle
        self.rng = np.random.default_rng(0)

    def reset(self, seed: int | None = None) -> None:
        self.rng = np.random.default_rng(seed)

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        surfaces = self.rng.uniform(-self.scale, self.scale, 3)
        return np.append(surfaces, self.throttle)
