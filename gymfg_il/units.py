"""Units and angles, each conversion written once.

JSBSim works in feet, knots and degrees; FlightGear's network, Foxglove and Tacview want
metres and radians. Multiply by a constant to convert (``altitude_ft * FT_TO_M``), divide to
convert back. Headings compare across north through ``wrap_180`` (a signed difference) and
``wrap_360`` (a compass direction).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, overload

if TYPE_CHECKING:
    import numpy as np
    import torch

FT_TO_M = 0.3048  # the international foot
KT_TO_MS = 1852.0 / 3600.0  # knots to m/s (a nautical mile is 1852 m)
KT_TO_FPS = KT_TO_MS / FT_TO_M  # knots to ft/s
FT_PER_NM = 6076.12  # feet per nautical mile, as charts round it

DEG_TO_RAD = math.pi / 180.0
RAD_TO_DEG = 180.0 / math.pi

# local north/east offsets treat the Earth as a sphere of its mean radius
EARTH_RADIUS_FT = 20902230.97
FT_PER_DEG = DEG_TO_RAD * EARTH_RADIUS_FT  # feet per degree of latitude


@overload
def wrap_180(angle_deg: float) -> float: ...
@overload
def wrap_180(angle_deg: np.ndarray) -> np.ndarray: ...
@overload
def wrap_180(angle_deg: torch.Tensor) -> torch.Tensor: ...
def wrap_180(angle_deg: Any) -> Any:
    """``angle_deg`` folded into [-180, 180): the signed turn a difference of headings is."""
    return (angle_deg + 180.0) % 360.0 - 180.0


@overload
def wrap_360(angle_deg: float) -> float: ...
@overload
def wrap_360(angle_deg: np.ndarray) -> np.ndarray: ...
def wrap_360(angle_deg: Any) -> Any:
    """``angle_deg`` folded into [0, 360): a compass direction."""
    return angle_deg % 360.0
