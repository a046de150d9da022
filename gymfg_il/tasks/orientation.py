"""Angles: wrapping and signed differences, so headings compare across north."""

from __future__ import annotations

import math

from gymfg_il.units import KT_TO_FPS, wrap_180, wrap_360

__all__ = [
    "angle_difference_deg",
    "bank_for_turn_rate",
    "relative_heading_deg",
    "wrap_180",
    "wrap_360",
]


def angle_difference_deg(to_deg: float, from_deg: float) -> float:
    """Signed shortest turn from ``from_deg`` to ``to_deg``, in [-180, 180)."""
    return wrap_180(to_deg - from_deg)


def relative_heading_deg(own: object, other: object) -> float:
    """How far ``other``'s heading is turned from ``own``'s (StateViews with heading_deg)."""
    return angle_difference_deg(other.heading_deg, own.heading_deg)  # type: ignore[attr-defined]


def bank_for_turn_rate(turn_rate_deg_s: float, true_airspeed_kts: float) -> float:
    """Bank angle (deg) of a coordinated turn at ``turn_rate_deg_s``."""
    v_fps = true_airspeed_kts * KT_TO_FPS
    return math.degrees(math.atan(math.radians(turn_rate_deg_s) * v_fps / 32.174))
