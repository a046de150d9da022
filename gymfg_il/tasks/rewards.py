"""What a reward function receives, and small shaping functions to build rewards from.

A reward is any ``Callable[[RewardContext], float]``. The context holds the aircraft's previous
and current state (``StateView``), its previous and current action, the states of the aircraft
named in its team's ``reward_function_targets`` (teammates in full, opponents only as the
environment lets them be seen), and, when a task asks for a window, the longer history.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from gymfg_il.sim.properties import StateView


@dataclass(slots=True)
class RewardContext:
    """Everything a reward may look at for one aircraft at one step.

    Attributes:
        state: the state after this step.
        prev_state: the state before it.
        action: the action applied at this step ``[aileron, elevator, rudder, throttle]``.
        prev_action: the action applied at the step before.
        targets: callsign -> state of each aircraft in the team's reward targets that is
            there to be seen: one that terminated before this step, or an online opponent
            the server does not show (not joined yet, or left), is absent, so a reward reads
            ``ctx.targets.get(callsign)`` and decides what absence is worth.
        history: the last ``history_window`` (state, action) pairs before ``prev_state``,
            oldest first, as arrays in catalogue order (empty unless the task asks for it).
        target: the task's current target value, if it has one.
        step: agent steps taken in this episode.
        dt: seconds per agent step.
    """

    state: StateView
    prev_state: StateView
    action: np.ndarray
    prev_action: np.ndarray
    targets: dict[str, StateView] = field(default_factory=dict)
    history: deque[tuple[np.ndarray, np.ndarray]] = field(default_factory=deque)
    target: float | None = None
    step: int = 0
    dt: float = 0.1


RewardFn = Callable[[RewardContext], float]


def closeness(error: float, scale: float) -> float:
    """1 at zero error, falling exponentially: exp(-|error| / scale)."""
    return math.exp(-abs(error) / scale)


def gaussian(error: float, scale: float) -> float:
    """1 at zero error, a Gaussian bump of width ``scale``."""
    return math.exp(-((error / scale) ** 2))


def action_change(prev_action: np.ndarray, action: np.ndarray) -> float:
    """Mean absolute change of the three surfaces between two steps (0 = perfectly smooth)."""
    if type(action) is np.ndarray and type(prev_action) is np.ndarray:
        # as Python floats: the same doubles at a third of numpy scalars' cost
        a, b = action.tolist(), prev_action.tolist()
    else:
        a, b = action, prev_action
    return (abs(a[0] - b[0]) + abs(a[1] - b[1]) + abs(a[2] - b[2])) / 3.0
