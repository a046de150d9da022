"""Maneuvers flown over the ground: three gates in order, and an approach to a runway.

Positions are local north/east feet from a point of the plan (``maneuvers.local_ft``); the
plan records that point as latitude and longitude, so a judge needs nothing but the states.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from gymfg_il.aircraft import FlightProfile
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.tasks.grades import Measure
from gymfg_il.tasks.guidance import Line, ils_dots
from gymfg_il.tasks.maneuvers import ManeuverTask, Verdict, local_ft, size
from gymfg_il.tasks.rewards import closeness
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import FT_PER_NM, KT_TO_FPS, wrap_180, wrap_360

_ALT, _HDG, _VC = INDEX["altitude_ft"], INDEX["heading_deg"], INDEX["airspeed_kts"]
_LAT, _LON = INDEX["lat_deg"], INDEX["lon_deg"]
_ROLL = INDEX["roll_deg"]


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


class ApproachTask(ManeuverTask):
    """Capture and hold a 3 degree glide path and the runway centre line down to 200 ft above
    the threshold, at the approach speed.

    Observation: ``FLIGHT_VARS`` and ``heading_deg``, then:

    | entry | unit | meaning |
    | --- | --- | --- |
    | distance_ft | ft | distance to the threshold along the runway course (positive before it) |
    | centerline_offset_ft | ft | how far right of the extended centre line |
    | course_error_deg | deg | runway course - heading, wrapped |
    | glidepath_error_ft | ft | the path's altitude here (level below 200 ft) - altitude |
    | airspeed_kts_error | kt | approach speed - airspeed |
    | airspeed_kts_error_integral | kt·s | that error summed over the steps times dt (+/- 600) |
    | height_above_threshold_ft | ft | altitude - threshold elevation |

    Plan: a runway whose course is within 30 deg of the start heading, its threshold 3.5-4
    NM ahead along the course times the task's ``speed_scale`` (the approach speed over the
    c172p's: 3 for the f15, 2.9 for the A320, so every aircraft has about the same time to
    set up), the aircraft up to 1,500 ft either side of the centre line and 0-300 ft above
    (or up to 100 ft below) the glide path; approach speed ``FlightProfile.final_approach_kts``
    (1.4 x the aircraft's minimum airspeed: 70 kt for the c172p, 210 for the f15; 200 kt for
    the A320, which cannot hold the slower speed clean), the start 10-40 % faster (true
    airspeed). The judged final starts 2.5 NM out on every aircraft (about 800 ft above the
    threshold, where a pilot is stabilized).
    Reward: ``0.4 exp(-|glide path error| / 100) + 0.4 exp(-|offset| / 300) + 0.2
    exp(-|speed error| / 10)`` minus the smoothness term.
    Success: the aircraft reaches the decision height (200 ft above the threshold on the
    path), and from 2.5 NM out down to it stays within 100 ft of the glide path, 200 ft of
    the centre line and 10 kt of the approach speed. Grade: the glide-path, centre-line
    (localizer) and airspeed errors from 2.5 NM out to the decision height, and the bank
    there (of 15 deg, the most a stabilized final allows).
    Start and end: as every maneuver (module docstring); 180 s episodes on every aircraft
    (the final grows with the approach speed instead).
    """

    name = "approach"
    episode_time_s = 180.0
    extra_names = (
        "distance_ft",
        "centerline_offset_ft",
        "course_error_deg",
        "glidepath_error_ft",
        "airspeed_kts_error",
        "airspeed_kts_error_integral",
        "height_above_threshold_ft",
    )
    tracked_entry = ("altitude_ft", "glidepath_error_ft", 100.0)
    integral_limit = 600.0
    glide_deg = 3.0
    decision_height_ft = 200.0
    hold_from_nm = 2.5
    tolerances = {"glide path": 100.0, "centre line": 200.0, "airspeed": 10.0}  # noqa: RUF012
    # the bank a stabilized final allows (the FAA's Airplane Flying Handbook: no more than
    # 15 deg on final); graded, never a success rule
    final_bank_deg = 15.0
    # the runway course and the approach speed as bugs; localizer and glide-slope needles in
    # dots; the distance to the threshold, the offsets in ft, the height above the threshold
    guidance = (
        Line("runway_course_deg", "deg", "heading", "bug", "runway course"),
        Line("approach_kts", "kt", "airspeed", "bug", "approach speed"),
        Line(
            "localizer_dots", "dot", "localizer", "needle", "localizer (right of the centre line)"
        ),
        Line("glideslope_dots", "dot", "glideslope", "needle", "glide slope (below the path)"),
        Line("distance_ft", "ft", "panel", "guidance", "to the threshold"),
        Line("centerline_offset_ft", "ft", "panel", "guidance", "off the centre line"),
        Line("glidepath_error_ft", "ft", "panel", "guidance", "off the glide path"),
        Line("height_above_threshold_ft", "ft", "panel", "guidance", "height above the threshold"),
    )

    def guidance_values(self, observed: Mapping[str, float]) -> list[float]:
        o = observed
        distance = o["distance_ft"]
        needles = ils_dots(distance, o["centerline_offset_ft"], o["glidepath_error_ft"])
        return [
            wrap_360(o["heading_deg"] + o["course_error_deg"]),
            o["airspeed_kts"] + o["airspeed_kts_error"],
            *needles,
            distance,
            o["centerline_offset_ft"],
            o["glidepath_error_ft"],
            o["height_above_threshold_ft"],
        ]

    @classmethod
    def flown_kts(cls, profile: FlightProfile) -> float:
        """The approach speed (``FlightProfile.final_approach_kts``)."""
        return profile.final_approach_kts

    @classmethod
    def episode_time_for(cls, profile: FlightProfile) -> float:
        """180 s on every aircraft: the final grows with the approach speed instead."""
        return cls.episode_time_s

    def approach_kts(self) -> float:
        return self.flown_kts(self._profile())

    def initial_conditions(self, rng: np.random.Generator) -> InitialConditions:
        """Cruise altitude, any heading, 10-40 % above the approach speed (slowing from
        cruise would take most of the final)."""
        if self.start is not None:
            return self.start
        ic = super().initial_conditions(rng)
        speed = self.approach_kts() * float(rng.uniform(1.1, 1.4))
        return dataclasses.replace(ic, airspeed_kts=speed)

    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        scale = self.speed_scale()
        course = wrap_360(float(state[_HDG]) + float(rng.uniform(-30.0, 30.0)))
        distance = float(rng.uniform(3.5, 4.0)) * FT_PER_NM * scale
        offset = float(rng.uniform(-1500.0, 1500.0))
        c, s = math.cos(math.radians(course)), math.sin(math.radians(course))
        north, east = distance * c + offset * s, distance * s - offset * c
        lat0, lon0 = float(state[_LAT]), float(state[_LON])
        lat, lon = offset_position(lat0, lon0, north, east)
        tan = math.tan(math.radians(self.glide_deg))
        above = float(rng.uniform(-100.0, 300.0))  # the start above the path
        return {
            "threshold": [lat, lon],
            "course_deg": course,
            "threshold_ft": float(state[_ALT]) - distance * tan - above,
            "glide_deg": self.glide_deg,
            "approach_kts": self.approach_kts(),
            "decision_height_ft": self.decision_height_ft,
            "hold_from_ft": self.hold_from_nm * FT_PER_NM,
        }

    @staticmethod
    def geometry(plan: dict[str, Any], states: np.ndarray) -> dict[str, Any]:
        """Distance, offset and glide-path error of ``states`` (arrays or one state)."""
        north, east = local_ft(states, plan["threshold"])
        c = math.cos(math.radians(plan["course_deg"]))
        s = math.sin(math.radians(plan["course_deg"]))
        along = -(north * c + east * s)
        tan = math.tan(math.radians(plan["glide_deg"]))
        path = plan["threshold_ft"] + np.maximum(plan["decision_height_ft"], along * tan)
        return {
            "distance": along,
            "offset": -north * s + east * c,
            "glidepath": path - states[..., _ALT],
            "airspeed": plan["approach_kts"] - states[..., _VC],
        }

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        plan = self.plan
        g = self.geometry(plan, state)
        speed_error = float(g["airspeed"])
        # the throttle a memoryless policy cannot see: the speed loop's integral
        if step == 0:
            self._integral = 0.0
        else:
            limit = self.integral_limit
            self._integral = max(-limit, min(limit, self._integral + speed_error * self.dt))
        return [
            float(g["distance"]),
            float(g["offset"]),
            wrap_180(plan["course_deg"] - float(state[_HDG])),
            float(g["glidepath"]),
            speed_error,
            self._integral,
            float(state[_ALT]) - plan["threshold_ft"],
        ]

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        return (
            0.4 * closeness(extras[3], 100.0)
            + 0.4 * closeness(extras[1], 300.0)
            + 0.2 * closeness(extras[4], 10.0)
        )

    @classmethod
    def landmarks(cls, plan: dict[str, Any], step: int) -> list[Landmark]:
        """The runway: 150 ft wide, 5,000 ft long from the threshold along the course."""
        lat, lon = plan["threshold"]
        course, alt = plan["course_deg"], plan["threshold_ft"]
        return [Landmark("runway", lat, lon, alt, course, width_ft=150.0, length_ft=5000.0)]

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        g = cls.geometry(plan, states)
        tan = math.tan(math.radians(plan["glide_deg"]))
        at_dh = plan["decision_height_ft"] / tan
        reached = np.flatnonzero(g["distance"] <= at_dh)
        if not len(reached):
            left = (g["distance"][-1] - at_dh) / FT_PER_NM
            return Verdict(False, f"ended {left:.2f} NM short of the decision height")
        flown = slice(0, int(reached[0]) + 1)
        final = g["distance"][flown] <= plan["hold_from_ft"]
        how = " on average" if gusty else ""
        for key, what in (("glidepath", "glide path"), ("offset", "centre line")):
            worst = size(g[key][flown][final], gusty)
            if worst > cls.tolerances[what]:
                return Verdict(False, f"{worst:.0f} ft off the {what}{how} on final")
        worst = size(g["airspeed"][flown][final], gusty)
        if worst > cls.tolerances["airspeed"]:
            return Verdict(False, f"{worst:.1f} kt off the approach speed{how} on final")
        measures = tuple(
            Measure.of(what, unit, g[key][flown][final], cls.tolerances[what], mean=gusty)
            for key, what, unit in (
                ("glidepath", "glide path", "ft"),
                ("offset", "centre line", "ft"),
                ("airspeed", "airspeed", "kt"),
            )
        )
        bank = states[flown][final, _ROLL]
        measures += (Measure.of("bank", "deg", bank, cls.final_bank_deg, mean=gusty),)
        return Verdict(True, f"decision height at {reached[0] * dt:.1f} s, on the path", measures)
