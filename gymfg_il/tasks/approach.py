"""A maneuver flown over the ground: an approach to a runway, down its glide path.

Positions are local north/east feet from the runway's threshold (``maneuvers.local_ft``); the
plan records it as latitude and longitude, so the judge needs nothing but the states.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from gymfg_il.aircraft import FlightProfile
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.experts import Targets
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.tasks.grades import Measure
from gymfg_il.tasks.guidance import Line, ils_dots
from gymfg_il.tasks.maneuvers import ManeuverTask, Verdict, local_ft, size
from gymfg_il.tasks.rewards import closeness
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import FT_PER_NM, wrap_180, wrap_360

_ALT, _HDG, _VC = INDEX["altitude_ft"], INDEX["heading_deg"], INDEX["airspeed_kts"]
_LAT, _LON = INDEX["lat_deg"], INDEX["lon_deg"]
_ROLL = INDEX["roll_deg"]


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
    # from its expert's demonstrations, every loop (the airspeed's integral read once, through
    # the expert's term): still air, flown in gusts, 69 % against the controller's 75 %
    # (vertical: 31 %); from five, 100 % (vertical: 81 %; docs/results/memory.md)
    expert_memory = "loops"
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

    expert_targets = Targets(
        vertical_source="glidepath_error_ft",
        lateral="track",
        lateral_source="course_error_deg",
        track_source="centerline_offset_ft",
        track_gain=0.03,
        speed_source="airspeed_kts_error",
        relative=frozenset({"vertical", "lateral", "speed"}),
    )
    expert_on_display: ClassVar[Mapping[str, Any]] = {
        "lateral_source": "runway_course_deg",
        "speed_source": "approach_kts",
        "relative": frozenset({"vertical"}),
    }

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
