"""Foxglove's own messages in the log: the Map, the 3D panel and what the task aims at.

Per step and aircraft the writer adds a ``foxglove.FrameTransform`` and fills
``foxglove.LocationFix.heading`` and ``velocity``; per episode and aircraft a
``foxglove.SceneUpdate`` draws the aircraft in its own frame (so the transforms move it), the
task's target, redrawn while a dynamic target moves (``Aim``), and what the task places in
the world (``tasks.scenery``: the approach's runway, the waypoint gates; a formation's lead
gets a frame of its own, ``<callsign>/lead``, moved by a transform every step). Foxglove
matches these schemas by name and field layout: ``foxglove_schemas/`` holds them exactly as
``@foxglove/schemas`` 1.13.0 publishes them (MIT licence, Foxglove Technologies; see its
README).

Frames and conventions:

- ``enu``: a local East-North-Up tangent frame (metres) anchored at the first aircraft's
  position at the episode's reset, on the WGS84 ellipsoid. Logged altitudes (JSBSim's height
  above sea level) are used as ellipsoidal heights, as ``LocationFix.altitude`` does.
- ``<callsign>``: the aircraft's body frame, x forward, y left, z up (FLU, the 3D panel's
  convention). JSBSim's Euler angles (roll phi, pitch theta, heading psi) rotate local
  North-East-Down into body Forward-Right-Down; the same attitude from ENU into FLU is
  yaw = 90 deg - psi, pitch = -theta, roll = phi (z-y-x order).
- ``LocationFix.heading``: radians clockwise from north (Foxglove's definition), the true
  heading; ``velocity``: the velocity over the ground in ENU, m/s (JSBSim's body velocities
  u, v, w rotated by the attitude).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import FT_TO_M

SCHEMAS = Path(__file__).with_name("foxglove_schemas")
PARENT_FRAME = "enu"
_A = 6378137.0  # WGS84 semi-major axis, m
_E2 = 6.69437999014e-3  # WGS84 first eccentricity squared

# (length, span) in metres of the models drawn in 3D; others get the default
_SIZES = {"c172p": (8.3, 11.0), "f15": (19.4, 13.1), "A320": (37.6, 34.1)}
_DEFAULT_SIZE = (10.0, 10.0)
_TEAM_COLOURS = ((0.2, 0.45, 1.0), (1.0, 0.3, 0.25), (0.2, 0.8, 0.3), (0.9, 0.75, 0.1))
_TARGET_COLOUR = {"r": 0.1, "g": 0.9, "b": 0.4, "a": 0.25}
_PLANE_M = 4000.0  # side of the target-altitude plane
_LINE_M = 3000.0  # length of the target-heading line
_UNITS = {"ft": "ft", "deg": "deg", "kt": "kt"}
_RUNWAY_COLOUR = {"r": 0.3, "g": 0.3, "b": 0.32, "a": 1.0}
_GATE_COLOUR = {"r": 0.92, "g": 0.43, "b": 0.08, "a": 1.0}
_ROLL, _PITCH, _HEADING = INDEX["roll_deg"], INDEX["pitch_deg"], INDEX["heading_deg"]
_U, _V, _W = INDEX["u_fps"], INDEX["v_fps"], INDEX["w_fps"]


@cache
def schema(name: str) -> dict[str, Any]:
    """Foxglove's JSON schema ``name`` (``foxglove.FrameTransform``, ...)."""
    loaded: dict[str, Any] = json.loads((SCHEMAS / f"{name}.json").read_text())
    return loaded


def _ecef(lat_deg: float, lon_deg: float, alt_m: float) -> tuple[float, float, float]:
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    s = math.sin(lat)
    n = _A / math.sqrt(1.0 - _E2 * s * s)
    c = (n + alt_m) * math.cos(lat)
    return c * math.cos(lon), c * math.sin(lon), (n * (1.0 - _E2) + alt_m) * s


class LocalFrame:
    """The ``enu`` frame anchored at (``lat_deg``, ``lon_deg``, ``alt_m``)."""

    def __init__(self, lat_deg: float, lon_deg: float, alt_m: float) -> None:
        self.origin = _ecef(lat_deg, lon_deg, alt_m)
        self.alt_m = alt_m
        lat, lon = math.radians(lat_deg), math.radians(lon_deg)
        self._sl, self._cl = math.sin(lat), math.cos(lat)
        self._so, self._co = math.sin(lon), math.cos(lon)

    def enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> tuple[float, float, float]:
        x, y, z = _ecef(lat_deg, lon_deg, alt_m)
        ox, oy, oz = self.origin
        dx, dy, dz = x - ox, y - oy, z - oz
        sl, cl, so, co = self._sl, self._cl, self._so, self._co
        east = -so * dx + co * dy
        north = -sl * co * dx - sl * so * dy + cl * dz
        up = cl * co * dx + cl * so * dy + sl * dz
        return east, north, up


def attitude(
    roll_deg: float, pitch_deg: float, heading_deg: float, uvw_fps: tuple[float, float, float]
) -> tuple[dict[str, float], dict[str, float]]:
    """(quaternion ENU <- FLU body, ground velocity in ENU m/s) from JSBSim's Euler angles and
    body velocities (module docstring)."""
    phi, theta, psi = math.radians(roll_deg), math.radians(pitch_deg), math.radians(heading_deg)
    sf, cf = math.sin(phi), math.cos(phi)
    st, ct = math.sin(theta), math.cos(theta)
    sp, cp = math.sin(psi), math.cos(psi)
    u, v, w = uvw_fps
    # body FRD -> NED (the rows of the direction cosine matrix), then NED -> ENU
    north = ct * cp * u + (sf * st * cp - cf * sp) * v + (cf * st * cp + sf * sp) * w
    east = ct * sp * u + (sf * st * sp + cf * cp) * v + (cf * st * sp - sf * cp) * w
    down = -st * u + sf * ct * v + cf * ct * w
    velocity = {"x": east * FT_TO_M, "y": north * FT_TO_M, "z": -down * FT_TO_M}
    # z-y-x quaternion of yaw = pi/2 - psi, pitch = -theta, roll = phi
    hy, hp, hr = (math.pi / 2 - psi) / 2, -theta / 2, phi / 2
    cy, sy = math.cos(hy), math.sin(hy)
    cq, sq = math.cos(hp), math.sin(hp)
    cr, sr = math.cos(hr), math.sin(hr)
    rotation = {
        "x": sr * cq * cy - cr * sq * sy,
        "y": cr * sq * cy + sr * cq * sy,
        "z": cr * cq * sy - sr * sq * cy,
        "w": cr * cq * cy + sr * sq * sy,
    }
    return rotation, velocity


def transform(
    frame: LocalFrame, ns: int, callsign: str, values: Sequence[float]
) -> tuple[dict[str, Any], tuple[float, float, float], dict[str, float]]:
    """(the FrameTransform ``enu`` -> ``callsign`` at log time ``ns`` of the catalogue-ordered
    state ``values``, its position in ``enu``, its ground velocity in ENU)."""
    where = frame.enu(values[0], values[1], values[2] * FT_TO_M)
    rotation, velocity = attitude(
        values[_ROLL], values[_PITCH], values[_HEADING], (values[_U], values[_V], values[_W])
    )
    message = {
        "timestamp": stamp(ns),
        "parent_frame_id": PARENT_FRAME,
        "child_frame_id": callsign,
        "translation": {"x": where[0], "y": where[1], "z": where[2]},
        "rotation": rotation,
    }
    return message, where, velocity


def pose_transform(frame: LocalFrame, ns: int, child: str, mark: Landmark) -> dict[str, Any]:
    """The FrameTransform ``enu`` -> ``child`` placing a landmark (a formation's lead)."""
    x, y, z = frame.enu(mark.lat_deg, mark.lon_deg, mark.alt_ft * FT_TO_M)
    rotation, _ = attitude(mark.roll_deg, mark.pitch_deg, mark.heading_deg, (0.0, 0.0, 0.0))
    return {
        "timestamp": stamp(ns),
        "parent_frame_id": PARENT_FRAME,
        "child_frame_id": child,
        "translation": {"x": x, "y": y, "z": z},
        "rotation": rotation,
    }


def scenery_entities(
    ns: int, callsign: str, marks: Sequence[Landmark], frame: LocalFrame
) -> list[dict[str, Any]]:
    """What ``callsign``'s task places in the world, in ``enu``: a runway as a flat slab from
    its threshold along its course, a gate as a loop around what counts as inside it, an
    aircraft (a formation's lead) in its own frame ``<callsign>/lead``."""
    cubes, lines, out = [], [], []
    for mark in marks:
        x, y, z = frame.enu(mark.lat_deg, mark.lon_deg, mark.alt_ft * FT_TO_M)
        psi = math.radians(mark.heading_deg)
        ahead, right = (math.sin(psi), math.cos(psi)), (math.cos(psi), -math.sin(psi))
        if mark.kind == "runway":
            half = mark.length_ft * FT_TO_M / 2
            yaw = (math.pi / 2 - psi) / 2
            pose = {
                "position": {"x": x + ahead[0] * half, "y": y + ahead[1] * half, "z": z},
                "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(yaw), "w": math.cos(yaw)},
            }
            size = {"x": 2 * half, "y": mark.width_ft * FT_TO_M, "z": 0.5}
            cubes.append({"pose": pose, "size": size, "color": _RUNWAY_COLOUR})
        elif mark.kind == "gate":
            w, h = mark.width_ft * FT_TO_M / 2, mark.length_ft * FT_TO_M / 2
            corners = [
                {"x": x + right[0] * a * w, "y": y + right[1] * a * w, "z": z + b * h}
                for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))
            ]
            lines.append(
                {
                    "type": 1,  # a loop
                    "pose": _pose(),
                    "thickness": 4.0,
                    "scale_invariant": True,
                    "points": corners,
                    "color": _GATE_COLOUR,
                    "colors": [],
                    "indices": [],
                }
            )
        elif mark.kind == "aircraft":
            lead = aircraft_entity(ns, f"{callsign}/lead", "", 1)
            out.append({**lead, "texts": [_text(f"{callsign}'s lead", 8.0)]})
    if cubes or lines:
        out.append(_entity(ns, PARENT_FRAME, f"{callsign}/scenery", cubes=cubes, lines=lines))
    return out


def stamp(ns: int) -> dict[str, int]:
    sec, nsec = divmod(ns, 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


_IDENTITY = {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}


def _pose(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> dict[str, Any]:
    return {"position": {"x": x, "y": y, "z": z}, "orientation": _IDENTITY}


def _colour(rgb: tuple[float, float, float], a: float = 1.0) -> dict[str, float]:
    return {"r": rgb[0], "g": rgb[1], "b": rgb[2], "a": a}


def _cube(x: float, z: float, size: tuple[float, float, float], colour: Any) -> dict[str, Any]:
    return {"pose": _pose(x, 0.0, z), "size": dict(zip("xyz", size, strict=True)), "color": colour}


def _entity(ns: int, frame: str, entity_id: str, **primitives: Any) -> dict[str, Any]:
    kinds = ("arrows", "cubes", "spheres", "cylinders", "lines", "triangles", "texts", "models")
    return {
        "timestamp": stamp(ns),
        "frame_id": frame,
        "id": entity_id,
        "lifetime": {"sec": 0, "nsec": 0},  # until replaced or deleted
        "frame_locked": True,
        "metadata": [],
        **{k: primitives.get(k, []) for k in kinds},
    }


def aircraft_entity(ns: int, callsign: str, model: str, team_index: int) -> dict[str, Any]:
    """The aircraft drawn in its own frame: fuselage, wings, tail, an arrow along its nose."""
    length, span = _SIZES.get(model, _DEFAULT_SIZE)
    body = _colour(_TEAM_COLOURS[team_index % len(_TEAM_COLOURS)])
    thick = length * 0.12
    cubes = [
        _cube(0.0, 0.0, (length, thick, thick), body),
        _cube(0.05 * length, 0.0, (0.18 * length, span, 0.03 * length), body),
        _cube(-0.42 * length, 0.0, (0.1 * length, 0.35 * span, 0.02 * length), body),
        _cube(-0.42 * length, 0.1 * length, (0.1 * length, 0.02 * length, 0.2 * length), body),
    ]
    arrow = {
        "pose": _pose(0.5 * length),
        "shaft_length": 0.6 * length,
        "shaft_diameter": 0.04 * length,
        "head_length": 0.15 * length,
        "head_diameter": 0.1 * length,
        "color": _colour((1.0, 1.0, 1.0), 0.8),
    }
    return _entity(ns, callsign, callsign, cubes=cubes, arrows=[arrow])


def _text(text: str, z: float) -> dict[str, Any]:
    return {
        "pose": _pose(0.0, 0.0, z),
        "billboard": True,
        "font_size": 14.0,
        "scale_invariant": True,
        "color": _colour((1.0, 1.0, 1.0)),
        "text": text,
    }


def target_entities(
    ns: int,
    callsign: str,
    task: dict[str, Any],
    target: float | None,
    where: tuple[float, float, float],
    frame: LocalFrame,
) -> list[dict[str, Any]]:
    """What ``callsign``'s task aims at, at ``target``, drawn around its ENU position
    ``where``: a target-altitude plane, a target-heading line, and a label naming the target
    for every task that has one."""
    variable = task.get("variable")
    if target is None or not isinstance(variable, str):
        return [_entity(ns, callsign, f"{callsign}/target", texts=[_text(callsign, 8.0)])]
    name, _, unit = variable.rpartition("_")
    label = f"{callsign}: {name.replace('_', ' ')} target {target:,.1f} {_UNITS.get(unit, unit)}"
    out = [_entity(ns, callsign, f"{callsign}/target", texts=[_text(label, 8.0)])]
    x, y, z = where
    if variable == "altitude_ft":
        up = target * FT_TO_M - frame.alt_m  # the tangent plane's drop is < 1.3 m at 4 km
        plane = {
            "pose": _pose(x, y, up),
            "size": {"x": _PLANE_M, "y": _PLANE_M, "z": 0.5},
            "color": _TARGET_COLOUR,
        }
        out.append(_entity(ns, PARENT_FRAME, f"{callsign}/aim", cubes=[plane]))
    elif variable == "heading_deg":
        psi = math.radians(target)
        end = {"x": x + _LINE_M * math.sin(psi), "y": y + _LINE_M * math.cos(psi), "z": z}
        line = {
            "type": 0,
            "pose": _pose(),
            "thickness": 3.0,
            "scale_invariant": True,
            "points": [{"x": x, "y": y, "z": z}, end],
            "color": {**_TARGET_COLOUR, "a": 0.9},
            "colors": [],
            "indices": [],
        }
        out.append(_entity(ns, PARENT_FRAME, f"{callsign}/aim", lines=[line]))
    return out


@dataclass
class Aim:
    """A moving target (a dynamic task's) and where the 3D view last drew it: it is redrawn
    when it has moved by half the task's tolerance."""

    task: dict[str, Any]
    index: int  # of the target in the observation
    value: float
    step: float

    @classmethod
    def of(cls, task: dict[str, Any], observation: np.ndarray) -> Aim | None:
        """The target of ``task`` (``Task.describe()``) at the reset ``observation``; None
        for tasks without one in their observation."""
        variable = task.get("variable")
        names = list(task.get("observation", ()))
        if not isinstance(variable, str) or f"{variable}_target" not in names:
            return None
        index = names.index(f"{variable}_target")
        tolerance = float(task.get("tolerance") or 1.0)
        return cls(task, index, float(observation[index]), tolerance / 2)

    @property
    def dynamic(self) -> bool:
        return bool(self.task.get("dynamic"))

    def moved(self, observation: np.ndarray | Sequence[float]) -> bool:
        value = float(observation[self.index])
        if abs(value - self.value) < self.step:
            return False
        self.value = value
        return True
