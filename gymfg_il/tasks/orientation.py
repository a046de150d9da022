"""Angles: wrapping and signed differences, so headings compare across north."""

from __future__ import annotations

import math


def wrap_180(angle_deg: float) -> float:
    """``angle_deg`` folded into [-180, 180)."""
    return (angle_deg + 180.0) % 360.0 - 180.0


def wrap_360(angle_deg: float) -> float:
    """``angle_deg`` folded into [0, 360)."""
    return angle_deg % 360.0


def angle_difference_deg(to_deg: float, from_deg: float) -> float:
    """Signed shortest turn from ``from_deg`` to ``to_deg``, in [-180, 180)."""
    return wrap_180(to_deg - from_deg)


def relative_heading_deg(own: object, other: object) -> float:
    """How far ``other``'s heading is turned from ``own``'s (StateViews with heading_deg)."""
    return angle_difference_deg(other.heading_deg, own.heading_deg)  # type: ignore[attr-defined]


def bank_for_turn_rate(turn_rate_deg_s: float, true_airspeed_kts: float) -> float:
    """Bank angle (deg) of a coordinated turn at ``turn_rate_deg_s``."""
    v_fps = true_airspeed_kts * 1.6878098571011957
    return math.degrees(math.atan(math.radians(turn_rate_deg_s) * v_fps / 32.174))
