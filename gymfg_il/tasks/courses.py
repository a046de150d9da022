"""A maneuver flown over the ground: three gates in order (the approach to a runway is
``tasks.approach``'s; its old path here keeps working for now, with a DeprecationWarning).

Positions are local north/east feet from a point of the plan (``maneuvers.local_ft``); the
plan records that point as latitude and longitude, so the judge needs nothing but the states.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from gymfg_il.moved import forward_names
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.experts import Targets
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.tasks.grades import Measure
from gymfg_il.tasks.guidance import Line
from gymfg_il.tasks.maneuvers import ManeuverTask, Verdict, local_ft
from gymfg_il.tasks.rewards import closeness
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import KT_TO_FPS, wrap_180, wrap_360

_ALT, _HDG = INDEX["altitude_ft"], INDEX["heading_deg"]
_LAT, _LON = INDEX["lat_deg"], INDEX["lon_deg"]
# names that moved out of this module, kept working for now
__getattr__ = forward_names(__name__, {"ApproachTask": "gymfg_il.tasks.approach"})


class WaypointsTask(ManeuverTask):
    """Fly through three gates in order.

    Observation: ``FLIGHT_VARS`` and ``heading_deg``, then:

    | entry | unit | meaning |
    | --- | --- | --- |
    | gate_distance_ft | ft | horizontal distance to the next gate (0 once all are passed) |
    | gate_bearing_error_deg | deg | the next gate's bearing (last: the last leg's) - heading |
    | gate_altitude_error_ft | ft | the next gate's altitude - altitude |
    | next_turn_deg | deg | the turn at the next gate onto the leg after it (0 at the last) |
    | gates_left | 1 | gates still to pass (3, 2, 1, 0) |

    Plan: three gates, each 25-32 s of cruise flight times the aircraft's
    ``maneuver_scale`` from the one before (1.4-1.8 km for the c172p, 8.7-11.2 km for the
    f15, 7.4-9.5 km for the A320: the same number of its own turn radii, so each turns onto
    the next leg as the c172p does), the first leg within 45 deg of the start heading, each
    later leg turned 20-60 deg either way, each gate 0-300 ft above or below the one before.
    A gate is passed within ``radius_ft`` (300) horizontally and ``altitude_tolerance_ft``
    (150) vertically, on every aircraft. Reward: ``0.5 exp(-distance / 3000) + 0.3
    exp(-|altitude error| / 150) + 0.2 exp(-|bearing error| / 20)`` minus the smoothness
    term. Success: all three gates passed, in order. Grade: how far from each gate's centre
    (of its radius) and above or below it (of its half height) the aircraft passed.
    Start and end: as every maneuver (module docstring); 120 s episodes on the c172p, times
    the aircraft's ``maneuver_scale`` (204 s on the f15, 247 on the A320).
    """

    name = "waypoints"
    episode_time_s = 120.0
    extra_names = (
        "gate_distance_ft",
        "gate_bearing_error_deg",
        "gate_altitude_error_ft",
        "next_turn_deg",
        "gates_left",
    )
    tracked_entry = ("altitude_ft", "gate_altitude_error_ft", 150.0)
    radius_ft = 300.0
    altitude_tolerance_ft = 150.0
    # the next gate's bearing and height as bugs, its distance, the gates left, the turn at it
    guidance = (
        Line("gate_bearing_deg", "deg", "heading", "bug", "bearing to the next gate"),
        Line("gate_altitude_ft", "ft", "altitude", "bug", "height of the next gate"),
        Line("gate_distance_ft", "ft", "panel", "guidance", "distance to the next gate"),
        Line("gates_left", "1", "panel", "guidance", "gates left"),
        Line("next_turn_deg", "deg", "panel", "guidance", "turn at the next gate"),
    )

    expert_targets = Targets(
        vertical_source="gate_altitude_error_ft",
        lateral="heading",
        lateral_source="gate_bearing_error_deg",
        relative=frozenset({"vertical", "lateral"}),
    )
    expert_on_display: ClassVar[Mapping[str, Any]] = {
        "vertical_source": "gate_altitude_ft",
        "lateral_source": "gate_bearing_deg",
        "relative": frozenset(),
    }

    def guidance_values(self, observed: Mapping[str, float]) -> list[float]:
        o = observed
        return [
            wrap_360(o["heading_deg"] + o["gate_bearing_error_deg"]),
            o["altitude_ft"] + o["gate_altitude_error_ft"],
            o["gate_distance_ft"],
            o["gates_left"],
            o["next_turn_deg"],
        ]

    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        profile = self._profile()
        speed, scale = profile.cruise_kts * KT_TO_FPS, profile.maneuver_scale
        course = float(state[_HDG]) + float(rng.uniform(-45.0, 45.0))
        north = east = 0.0
        alt = float(state[_ALT])
        gates = []
        for k in range(3):
            if k:
                course += float(rng.uniform(20.0, 60.0)) * (1.0 if rng.random() < 0.5 else -1.0)
            leg = speed * (float(rng.uniform(25.0, 32.0)) * scale)
            north += leg * math.cos(math.radians(course))
            east += leg * math.sin(math.radians(course))
            alt += float(rng.uniform(-300.0, 300.0))
            gates.append([north, east, alt])
        return {
            "origin": [float(state[_LAT]), float(state[_LON])],
            "gates": gates,
            "radius_ft": self.radius_ft,
            "altitude_tolerance_ft": self.altitude_tolerance_ft,
        }

    @staticmethod
    def _inside(gate: list[float], north: Any, east: Any, alt: Any, plan: dict[str, Any]) -> Any:
        horizontal = np.hypot(gate[0] - north, gate[1] - east) <= plan["radius_ft"]
        return horizontal & (np.abs(gate[2] - alt) <= plan["altitude_tolerance_ft"])

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        plan = self.plan
        gates = plan["gates"]
        north, east = local_ft(state, plan["origin"])
        alt, heading = float(state[_ALT]), float(state[_HDG])
        if step == 0:
            self._gate = 0
        if self._gate < len(gates) and self._inside(gates[self._gate], north, east, alt, plan):
            self._gate += 1
        k = self._gate
        if k == len(gates):  # all passed: hold the last leg's course and the last altitude
            (n0, e0, _), (n1, e1, a1) = gates[-2], gates[-1]
            course = math.degrees(math.atan2(e1 - e0, n1 - n0))
            return [0.0, wrap_180(course - heading), a1 - alt, 0.0, 0.0]
        gn, ge, ga = gates[k]
        bearing = math.degrees(math.atan2(ge - east, gn - north))
        turn = 0.0
        if k + 1 < len(gates):
            nn, ne, _ = gates[k + 1]
            turn = wrap_180(math.degrees(math.atan2(ne - ge, nn - gn)) - bearing)
        distance = math.hypot(gn - north, ge - east)
        return [distance, wrap_180(bearing - heading), ga - alt, turn, float(len(gates) - k)]

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        return (
            0.5 * closeness(extras[0], 3000.0)
            + 0.3 * closeness(extras[2], 150.0)
            + 0.2 * closeness(extras[1], 20.0)
        )

    @classmethod
    def landmarks(cls, plan: dict[str, Any], step: int) -> list[Landmark]:
        """The three gates, each facing the leg that leads to it, as wide and tall as what
        counts as inside (``tasks.scenery``)."""
        found, previous = [], (0.0, 0.0)
        for north, east, alt in plan["gates"]:
            facing = math.degrees(math.atan2(east - previous[1], north - previous[0]))
            lat, lon = offset_position(plan["origin"][0], plan["origin"][1], north, east)
            width, height = 2.0 * plan["radius_ft"], 2.0 * plan["altitude_tolerance_ft"]
            found.append(Landmark("gate", lat, lon, alt, facing, width_ft=width, length_ft=height))
            previous = (north, east)
        return found

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        north, east = local_ft(states, plan["origin"])
        alt = states[:, _ALT]
        at, off, high = 0, [], []
        for k, gate in enumerate(plan["gates"]):
            inside = np.flatnonzero(cls._inside(gate, north[at:], east[at:], alt[at:], plan))
            if not len(inside):
                closest = np.hypot(gate[0] - north[at:], gate[1] - east[at:]).min()
                return Verdict(
                    False, f"passed {k} of 3 gates; gate {k + 1} missed by {closest:.0f} ft"
                )
            at += int(inside[0]) + 1  # one gate per step, as flown
            off.append(math.hypot(gate[0] - north[at - 1], gate[1] - east[at - 1]))
            high.append(alt[at - 1] - gate[2])
        measures = (
            Measure.of("off the gate centres", "ft", off, plan["radius_ft"]),
            Measure.of("above the gates", "ft", high, plan["altitude_tolerance_ft"]),
        )
        return Verdict(True, f"all 3 gates passed, the last at {(at - 1) * dt:.1f} s", measures)
