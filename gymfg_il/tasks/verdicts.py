"""Whether a target was held: the success rule of the target tasks, in one place (evaluation
scores episodes with it, the manual window's debrief states it).

The error must stay within the tolerance through the last ``HOLD_S`` seconds; a moving
target's tolerance is ``TRACKING_FACTOR`` times the static one; in turbulence a gust carries
any aircraft past a calm-air tolerance for a moment, so there the error must average within
the tolerance over those seconds instead. Maneuvers judge themselves (``ManeuverTask.judge``).
"""

from __future__ import annotations

import numpy as np

HOLD_S = 10.0
TRACKING_FACTOR = 3.0


def allowed_error(tolerance: float, dynamic: bool) -> float:
    """The error a held target may show: the tolerance, wider for a moving target."""
    return tolerance * (TRACKING_FACTOR if dynamic else 1.0)


def held(
    errors: np.ndarray,
    tolerance: float,
    dynamic: bool,
    dt: float,
    gusty: bool = False,
    hold_s: float = HOLD_S,
) -> bool:
    """Whether ``errors`` (one per agent step) end held within the tolerance."""
    steps = max(1, round(hold_s / dt))
    tail = np.abs(np.asarray(errors))[-steps:]
    if len(tail) < steps:
        return False
    worst = tail.mean() if gusty else tail.max()
    return bool(worst <= allowed_error(tolerance, dynamic))
