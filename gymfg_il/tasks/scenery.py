"""What a task puts in the world for a camera to draw: runways, gates, other aircraft.

A ``Landmark`` is a position (geodetic latitude and longitude, altitude in ft), an
orientation and a size; ``viz.camera`` draws it. Tasks say what they place through
``landmarks(plan, step)`` (a classmethod, so a logged plan is enough to redraw a flight);
tasks without anything to show place nothing. ``tasks.library.task_landmarks`` finds them
for a task named in a record.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.moved import forward_names
from gymfg_il.sim.properties import INDEX

KINDS = ("runway", "gate", "aircraft")
# names that moved out of this module, kept working for now (``task_landmarks`` resolves a
# task's name, the library's job)
__getattr__ = forward_names(__name__, {"task_landmarks": "gymfg_il.tasks.library"})


@dataclass(frozen=True, slots=True)
class Landmark:
    """One thing to draw.

    Attributes:
        kind: ``runway`` (a flat strip from its position along ``heading_deg``), ``gate``
            (an upright frame centred on its position, facing ``heading_deg``) or
            ``aircraft`` (a model at its position and attitude).
        lat_deg, lon_deg, alt_ft: where it is.
        heading_deg, roll_deg, pitch_deg: its orientation.
        width_ft, length_ft: runway width and length; gate width and height; aircraft
            span and length.
        highlight: draw it as the one that matters now (the next gate: a camera in legible
            mode paints it in its own colour with a thicker frame; the default mode, which
            makes dataset images, ignores it).
    """

    kind: str
    lat_deg: float
    lon_deg: float
    alt_ft: float
    heading_deg: float = 0.0
    roll_deg: float = 0.0
    pitch_deg: float = 0.0
    width_ft: float = 36.0
    length_ft: float = 27.0
    highlight: bool = False


def aircraft_landmark(state: np.ndarray, span_ft: float = 36.0) -> Landmark:
    """Another aircraft, drawn from its catalogue-ordered state."""
    return Landmark(
        "aircraft",
        float(state[INDEX["lat_deg"]]),
        float(state[INDEX["lon_deg"]]),
        float(state[INDEX["altitude_ft"]]),
        float(state[INDEX["heading_deg"]]),
        float(state[INDEX["roll_deg"]]),
        float(state[INDEX["pitch_deg"]]),
        span_ft,
        0.75 * span_ft,
    )


def landmarks_of(task: Any, plan: dict[str, Any] | None, step: int) -> list[Landmark]:
    """What ``task`` (a Task class or instance) places at agent ``step`` of an episode with
    ``plan`` (``Task.describe()["plan"]``); nothing without a plan."""
    found = getattr(task, "landmarks", None)
    return list(found(plan, step)) if plan and found is not None else []
