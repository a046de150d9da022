"""Each task's readings beyond the primary instruments: its targets as bugs and the guidance a
pilot expects for it, as lines (``Line``: a reading's declaration; ``display.readings`` says
what a reading is and gives each line its value).

- target tasks: the target as a bug on its instrument (a slip ball's mark for sideslip);
- level: the start altitude and heading as bugs;
- turn: the altitude and the new heading as bugs, and the turn still to fly with its
  direction;
- climb-turn: the new altitude and heading as bugs;
- waypoints: the next gate's bearing and height as bugs, its distance, the gates left and
  the turn at it;
- formation: the lead's heading and bank as bugs; the slot's offset (behind/ahead, right/left,
  below/above) and the closure rate, in words and on a diagram;
- approach: the runway course and the approach speed as bugs; localizer and glide-slope
  needles in dots; the distance to the threshold, the offsets in ft, the height above the
  threshold.

Every value comes from the task's own observation of the same step (what the avionics
compute: an ILS receiver measures the deviation, a GPS the gate's bearing), so the window and
the task agree by construction.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gymfg_il.display.instruments import PRIMARY
from gymfg_il.sim.properties import BY_NAME
from gymfg_il.units import wrap_360

# an ILS: localizer full scale (2 dots) 2.5 deg, glide slope full scale 0.7 deg; the
# localizer's antenna stands beyond the runway's far end
LOCALIZER_DEG_PER_DOT = 1.25
GLIDESLOPE_DEG_PER_DOT = 0.35
RUNWAY_FT = 5000.0


@dataclass(frozen=True, slots=True)
class Line:
    """A reading's declaration: everything but its value."""

    name: str
    unit: str
    instrument: str
    role: str
    label: str


Values = Callable[[Any, dict[str, float]], list[float]]


def _bug(name: str, label: str) -> Line:
    variable = name.removesuffix("_target")
    return Line(name, BY_NAME[variable].unit, PRIMARY[variable], "bug", label)


TURN = (
    _bug("altitude_ft_target", "altitude to hold"),
    _bug("heading_deg_target", "new heading"),
    Line("turn_remaining_deg", "deg", "panel", "guidance", "turn still to fly"),
)
CLIMB_TURN = (_bug("altitude_ft_target", "new altitude"), _bug("heading_deg_target", "new heading"))
WAYPOINTS = (
    Line("gate_bearing_deg", "deg", "heading", "bug", "bearing to the next gate"),
    Line("gate_altitude_ft", "ft", "altitude", "bug", "height of the next gate"),
    Line("gate_distance_ft", "ft", "panel", "guidance", "distance to the next gate"),
    Line("gates_left", "1", "panel", "guidance", "gates left"),
    Line("next_turn_deg", "deg", "panel", "guidance", "turn at the next gate"),
)
FORMATION = (
    Line("lead_heading_deg", "deg", "heading", "bug", "the lead's heading"),
    Line("lead_roll_deg", "deg", "bank", "bug", "the lead's bank"),
    Line("behind_slot_ft", "ft", "slot", "guidance", "off the slot, along"),
    Line("right_of_slot_ft", "ft", "slot", "guidance", "off the slot, across"),
    Line("below_slot_ft", "ft", "slot", "guidance", "off the slot, height"),
    Line("behind_slot_rate_fps", "ft/s", "slot", "guidance", "closure"),
)
APPROACH = (
    Line("runway_course_deg", "deg", "heading", "bug", "runway course"),
    Line("approach_kts", "kt", "airspeed", "bug", "approach speed"),
    Line("localizer_dots", "dot", "localizer", "needle", "localizer (right of the centre line)"),
    Line("glideslope_dots", "dot", "glideslope", "needle", "glide slope (below the path)"),
    Line("distance_ft", "ft", "panel", "guidance", "to the threshold"),
    Line("centerline_offset_ft", "ft", "panel", "guidance", "off the centre line"),
    Line("glidepath_error_ft", "ft", "panel", "guidance", "off the glide path"),
    Line("height_above_threshold_ft", "ft", "panel", "guidance", "height above the threshold"),
)


def _turn(task: Any, o: dict[str, float]) -> list[float]:
    plan = task.plan
    heading = wrap_360(plan["start_heading_deg"] + plan["turn_deg"])
    return [plan["altitude_ft"], heading, o["turn_remaining_deg"]]


def _climb_turn(task: Any, o: dict[str, float]) -> list[float]:
    return [o["altitude_ft_target"], o["heading_deg_target"]]


def _waypoints(task: Any, o: dict[str, float]) -> list[float]:
    return [
        wrap_360(o["heading_deg"] + o["gate_bearing_error_deg"]),
        o["altitude_ft"] + o["gate_altitude_error_ft"],
        o["gate_distance_ft"],
        o["gates_left"],
        o["next_turn_deg"],
    ]


def _formation(task: Any, o: dict[str, float]) -> list[float]:
    return [
        wrap_360(o["heading_deg"] + o["lead_heading_error_deg"]),
        o["lead_roll_deg"],
        o["behind_slot_ft"],
        o["right_of_slot_ft"],
        o["below_slot_ft"],
        o["behind_slot_rate_fps"],
    ]


def _approach(task: Any, o: dict[str, float]) -> list[float]:
    distance = o["distance_ft"]
    lateral = math.degrees(math.atan2(o["centerline_offset_ft"], max(distance + RUNWAY_FT, 100.0)))
    vertical = math.degrees(math.atan2(o["glidepath_error_ft"], max(distance, 100.0)))
    return [
        wrap_360(o["heading_deg"] + o["course_error_deg"]),
        o["airspeed_kts"] + o["airspeed_kts_error"],
        lateral / LOCALIZER_DEG_PER_DOT,
        vertical / GLIDESLOPE_DEG_PER_DOT,
        distance,
        o["centerline_offset_ft"],
        o["glidepath_error_ft"],
        o["height_above_threshold_ft"],
    ]


MANEUVERS: dict[str, tuple[tuple[Line, ...], Values]] = {
    "turn": (TURN, _turn),
    "climb-turn": (CLIMB_TURN, _climb_turn),
    "waypoints": (WAYPOINTS, _waypoints),
    "formation": (FORMATION, _formation),
    "approach": (APPROACH, _approach),
}


def _level(task: Any, o: dict[str, float]) -> list[float]:
    return [task.start_altitude, task.start_heading]


def guide(task: Any) -> tuple[tuple[Line, ...], Values]:
    """The lines ``task`` shows and how their values come from its observation."""
    from gymfg_il.tasks.library import LevelFlightTask
    from gymfg_il.tasks.targets import TargetTask

    name = getattr(task, "name", None)
    if name in MANEUVERS:
        return MANEUVERS[str(name)]
    if isinstance(task, LevelFlightTask):
        held = (
            _bug("altitude_ft_target", "altitude to hold"),
            _bug("heading_deg_target", "heading"),
        )
        return held, _level
    if isinstance(task, TargetTask):
        target = f"{task.family.variable}_target"
        instrument = PRIMARY[task.family.variable]
        label = "target " + {"slip": "sideslip"}.get(instrument, instrument)

        def _target(task: Any, o: dict[str, float]) -> list[float]:
            return [o[target]]

        return (_bug(target, label),), _target
    # a task of the user's own: a bug for every target of a primary instrument it observes
    bugs = tuple(
        _bug(n, n.replace("_", " "))
        for n in task.observation_names
        if n.endswith("_target") and n.removesuffix("_target") in PRIMARY
    )

    def _targets(task: Any, o: dict[str, float]) -> list[float]:
        return [o[line.name] for line in bugs]

    return bugs, _targets


def reading_names(task: Any) -> tuple[str, ...]:
    """The names of every reading ``task`` is shown with, primary instruments first."""
    return (*PRIMARY, *(line.name for line in guide(task)[0]))
