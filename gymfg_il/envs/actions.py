"""Checking actions before they reach JSBSim: shape, finiteness, and the contract's ranges.

An action is ``[aileron, elevator, rudder, throttle]``: the surfaces in [-1, 1], throttle in
[0, 1]. Values outside are clipped (policies with unbounded outputs are common); NaN, inf and
wrong shapes are errors that say what was given.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gymfg_il.errors import ActionError
from gymfg_il.sim.properties import ACTION_NAMES

Controls = tuple[float, float, float, float]


def _bad_values(values: Sequence[float], names: Sequence[str]) -> list[str]:
    return [f"{n}={v!r}" for n, v in zip(names, values, strict=True) if not np.isfinite(v)]


def controls(action: object, who: str = "action") -> Controls:
    """One aircraft's action as four clipped floats; raises ActionError for bad input."""
    if type(action) is np.ndarray and action.shape == (4,) and action.dtype.kind == "f":
        a0, a1, a2, a3 = action.tolist()
    else:
        arr = _as_array(action, who)
        if arr.shape != (4,):
            raise ActionError(
                f"{who} has shape {arr.shape}; expected (4,) = [aileron, elevator, rudder, "
                "throttle]"
            )
        a0, a1, a2, a3 = arr.tolist()
    # x - x is 0.0 for finite x and NaN for NaN or +/-inf.
    if a0 - a0 != 0.0 or a1 - a1 != 0.0 or a2 - a2 != 0.0 or a3 - a3 != 0.0:
        bad = _bad_values((a0, a1, a2, a3), ACTION_NAMES)
        raise ActionError(
            f"{who} has non-finite values ({', '.join(bad)}); nothing was sent to JSBSim. "
            "Check the agent's output (e.g. a policy fed unnormalised observations)"
        )
    return (  # clipped, written out: this runs at every step of every aircraft
        -1.0 if a0 < -1.0 else 1.0 if a0 > 1.0 else a0,
        -1.0 if a1 < -1.0 else 1.0 if a1 > 1.0 else a1,
        -1.0 if a2 < -1.0 else 1.0 if a2 > 1.0 else a2,
        0.0 if a3 < 0.0 else 1.0 if a3 > 1.0 else a3,
    )


def clip(action: object, who: str = "action") -> np.ndarray:
    """One aircraft's action clipped to the contract (float64, shape (4,)): the one clipping
    every pilot's output goes through; NaN, inf or a wrong shape raise ActionError."""
    return np.array(controls(action, who))


def team_controls(action: object, callsigns: Sequence[str]) -> list[Controls]:
    """A team's stacked action (``np.hstack`` of one 4-vector per aircraft) split and checked."""
    n = len(callsigns)
    arr = _as_array(action, "team action")
    if arr.shape == (n, 4):
        arr = arr.reshape(-1)
    if arr.shape != (4 * n,):
        raise ActionError(
            f"team action has shape {arr.shape}; expected ({4 * n},): np.hstack of one "
            f"[aileron, elevator, rudder, throttle] per aircraft, in roster order {list(callsigns)}"
        )
    return [controls(arr[4 * i : 4 * i + 4], f"action of {c!r}") for i, c in enumerate(callsigns)]


def _as_array(action: object, who: str) -> np.ndarray:
    try:
        arr = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ActionError(f"{who} {action!r} is not an array of numbers ({err})") from None
    return arr
