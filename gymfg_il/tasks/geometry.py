"""Where aircraft are relative to each other: distance, bearing, altitude difference.

Functions take StateViews (anything with ``lat_deg``, ``lon_deg``, ``altitude_ft``; an opponent
view has them by default), so a reward is one lambda, e.g.
``lambda ctx: -distance_ft(ctx.state, ctx.targets["red-two"]) / 1000``.
"""

from __future__ import annotations

import math

from gymfg_il.sim.initial import ecef_ft

_EARTH_RADIUS_FT = 20902230.97  # mean radius, for local north/east offsets


def distance_ft(a: object, b: object) -> float:
    """Straight-line distance between two aircraft (ft), from their geodetic positions."""
    ax, ay, az = ecef_ft(a.lat_deg, a.lon_deg, a.altitude_ft)  # type: ignore[attr-defined]
    bx, by, bz = ecef_ft(b.lat_deg, b.lon_deg, b.altitude_ft)  # type: ignore[attr-defined]
    return math.sqrt((ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2)


def horizontal_offset_ft(a: object, b: object) -> tuple[float, float]:
    """(north, east) of ``b`` seen from ``a`` in ft, on a local flat-earth approximation."""
    lat_a, lon_a = a.lat_deg, a.lon_deg  # type: ignore[attr-defined]
    lat_b, lon_b = b.lat_deg, b.lon_deg  # type: ignore[attr-defined]
    north = math.radians(lat_b - lat_a) * _EARTH_RADIUS_FT
    dlon = (lon_b - lon_a + 180.0) % 360.0 - 180.0
    east = math.radians(dlon) * _EARTH_RADIUS_FT * math.cos(math.radians((lat_a + lat_b) / 2))
    return north, east


def bearing_deg(a: object, b: object) -> float:
    """True bearing from ``a`` to ``b`` in [0, 360)."""
    north, east = horizontal_offset_ft(a, b)
    return math.degrees(math.atan2(east, north)) % 360.0


def altitude_difference_ft(a: object, b: object) -> float:
    """``b``'s altitude minus ``a``'s (ft)."""
    return float(b.altitude_ft - a.altitude_ft)  # type: ignore[attr-defined]


def offset_position(
    lat_deg: float, lon_deg: float, north_ft: float, east_ft: float
) -> tuple[float, float]:
    """The (lat, lon) ``north_ft`` north and ``east_ft`` east of a point."""
    lat = lat_deg + math.degrees(north_ft / _EARTH_RADIUS_FT)
    lon = lon_deg + math.degrees(east_ft / (_EARTH_RADIUS_FT * math.cos(math.radians(lat_deg))))
    return lat, (lon + 180.0) % 360.0 - 180.0
