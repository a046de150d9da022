"""What a task shows a pilot beyond the primary instruments: its guidance lines.

A task declares its lines (``Task.guidance_lines()``: each a ``Line``, a reading's declaration,
everything but its value) and how their values come from its own observation of the same step
(``Task.guidance_values(observed)``: what the avionics compute; an ILS receiver measures the
deviation, a GPS the gate's bearing), so the window (``display.readings``) and the task agree
by construction:

- a target as a bug on the instrument of its variable (``bug``; a slip ball's mark for
  sideslip), which is what a task of your own shows of every target of a primary instrument
  it observes (``target_bugs``);
- the guidance a pilot expects for a maneuver: the turn still to fly, the next gate's
  distance, the formation slot's offsets, the ILS needles in dots (``ils_dots``).

``PRIMARY`` names the primary flight display's instruments: which flight variable each one
shows (the display draws a value there; a task puts its targets there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from gymfg_il.sim.properties import BY_NAME

# each flight variable and the instrument that shows it
PRIMARY: dict[str, str] = {
    "airspeed_kts": "airspeed",
    "altitude_ft": "altitude",
    "vertical_speed_fps": "vertical_speed",
    "roll_deg": "bank",
    "pitch_deg": "pitch",
    "heading_deg": "heading",
    "beta_deg": "slip",
}

# an ILS: localizer full scale (2 dots) 2.5 deg, glide slope full scale 0.7 deg; the
# localizer's antenna stands beyond the runway's far end
LOCALIZER_DEG_PER_DOT = 1.25
GLIDESLOPE_DEG_PER_DOT = 0.35
RUNWAY_FT = 5000.0


@dataclass(frozen=True, slots=True)
class Line:
    """A reading's declaration: everything but its value (``display.readings.Reading``).

    Attributes:
        name: what it is (``altitude_ft_target``, ``gate_distance_ft``).
        unit: the catalogue's unit of its value.
        instrument: where it is drawn: a primary instrument (``PRIMARY``), the ILS scales
            (``localizer``, ``glideslope``), the formation slot diagram (``slot``) or the
            guidance panel (``panel``).
        role: ``bug`` (a target on its instrument), ``needle`` (an ILS deviation in dots)
            or ``guidance`` (a number with its words).
        label: the words a person reads beside it.
    """

    name: str
    unit: str
    instrument: str
    role: str
    label: str


def bug(name: str, label: str) -> Line:
    """The target ``name`` (``<variable>_target``) as a bug on its variable's instrument."""
    variable = name.removesuffix("_target")
    return Line(name, BY_NAME[variable].unit, PRIMARY[variable], "bug", label)


def target_bugs(observation_names: tuple[str, ...]) -> tuple[Line, ...]:
    """A bug for every target of a primary instrument among ``observation_names``."""
    return tuple(
        bug(n, n.replace("_", " "))
        for n in observation_names
        if n.endswith("_target") and n.removesuffix("_target") in PRIMARY
    )


def ils_dots(distance_ft: float, offset_ft: float, glidepath_ft: float) -> tuple[float, float]:
    """(localizer, glide slope) needles in dots, of an aircraft ``distance_ft`` before the
    threshold, ``offset_ft`` right of the centre line and ``glidepath_ft`` below the path."""
    lateral = math.degrees(math.atan2(offset_ft, max(distance_ft + RUNWAY_FT, 100.0)))
    vertical = math.degrees(math.atan2(glidepath_ft, max(distance_ft, 100.0)))
    return lateral / LOCALIZER_DEG_PER_DOT, vertical / GLIDESLOPE_DEG_PER_DOT


def reading_names(task: Any) -> tuple[str, ...]:
    """The names of every reading ``task`` is shown with, primary instruments first."""
    return (*PRIMARY, *(line.name for line in task.guidance_lines()))
