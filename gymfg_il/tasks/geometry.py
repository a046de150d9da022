"""Where aircraft are relative to each other: distance, bearing, altitude difference.

Functions take StateViews (anything with ``lat_deg``, ``lon_deg``, ``altitude_ft``; an opponent
view has them by default), so a reward is one lambda, e.g.
``lambda ctx: -distance_ft(ctx.state, ctx.targets["red-two"]) / 1000``.
"""

from __future__ import annotations

import math

from gymfg_il.sim.initial import ecef_ft
from gymfg_il.units import EARTH_RADIUS_FT, wrap_180, wrap_360


def distance_ft(a: object, b: object) -> float:
    """Straight-line distance between two aircraft (ft), from their geodetic positions."""
    ax, ay, az = ecef_ft(a.lat_deg, a.lon_deg, a.altitude_ft)  # type: ignore[attr-defined]
    bx, by, bz = ecef_ft(b.lat_deg, b.lon_deg, b.altitude_ft)  # type: ignore[attr-defined]
    return math.sqrt((ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2)


def horizontal_offset_ft(a: object, b: object) -> tuple[float, float]:
    """(north, east) of ``b`` seen from ``a`` in ft, on a local flat-earth approximation."""
    lat_a, lon_a = a.lat_deg, a.lon_deg  # type: ignore[attr-defined]
    lat_b, lon_b = b.lat_deg, b.lon_deg  # type: ignore[attr-defined]
    north = math.radians(lat_b - lat_a) * EARTH_RADIUS_FT
    dlon = wrap_180(lon_b - lon_a)
    east = math.radians(dlon) * EARTH_RADIUS_FT * math.cos(math.radians((lat_a + lat_b) / 2))
    return north, east


def bearing_deg(a: object, b: object) -> float:
    """True bearing from ``a`` to ``b`` in [0, 360)."""
    north, east = horizontal_offset_ft(a, b)
    return wrap_360(math.degrees(math.atan2(east, north)))


def altitude_difference_ft(a: object, b: object) -> float:
    """``b``'s altitude minus ``a``'s (ft)."""
    return float(b.altitude_ft - a.altitude_ft)  # type: ignore[attr-defined]


def offset_position(
    lat_deg: float, lon_deg: float, north_ft: float, east_ft: float
) -> tuple[float, float]:
    """The (lat, lon) ``north_ft`` north and ``east_ft`` east of a point."""
    lat = lat_deg + math.degrees(north_ft / EARTH_RADIUS_FT)
    lon = lon_deg + math.degrees(east_ft / (EARTH_RADIUS_FT * math.cos(math.radians(lat_deg))))
    return lat, wrap_180(lon)
