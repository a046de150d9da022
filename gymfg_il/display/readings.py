"""The display model: what a person at the window is given, reading by reading.

A ``Reading`` is one value the window draws, with its name, unit, the instrument it is drawn
on and its role there: the aircraft's own value (``value``: the pointer of a tape, the
attitude), a target (``bug``: a magenta mark on that instrument), a needle (``needle``: an
ILS deviation in dots) or a line of the guidance panel (``guidance``: a number with its
words). ``display_of(task, state, step)`` gives every reading for one task and state; the
window draws exactly these (``cockpit.windows.gui`` records what it drew, and a test holds it
to the model), and the synthetic pilot reads only these (``manual.perception``).

Values keep the catalogue's units (``vertical_speed_fps`` in ft/s, distances in ft); the
instrument draws them the way pilots read them (ft/min, NM).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.sim.properties import BY_NAME, INDEX
from gymfg_il.tasks.guidance import PRIMARY

ROLES = ("value", "bug", "needle", "guidance")


@dataclass(frozen=True, slots=True)
class Reading:
    """One value the window draws.

    Attributes:
        name: what it is (a catalogue or task name: ``altitude_ft``, ``altitude_ft_target``,
            ``gate_distance_ft``).
        value: its value, in ``unit``.
        unit: the catalogue's unit of the value.
        instrument: where it is drawn: a PFD instrument (``airspeed``, ``altitude``,
            ``vertical_speed``, ``bank``, ``pitch``, ``heading``, ``slip``), the ILS scales
            (``localizer``, ``glideslope``), the formation slot diagram (``slot``) or the
            guidance panel (``panel``).
        role: ``value``, ``bug``, ``needle`` or ``guidance`` (module docstring).
        label: the words a person reads beside it.
    """

    name: str
    value: float
    unit: str
    instrument: str
    role: str
    label: str


@dataclass(frozen=True)
class Display:
    """Every reading of one frame, in drawing order (primary instruments first)."""

    readings: tuple[Reading, ...]

    def __iter__(self) -> Iterator[Reading]:
        return iter(self.readings)

    def __getitem__(self, name: str) -> float:
        for reading in self.readings:
            if reading.name == name:
                return reading.value
        raise KeyError(name)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(r.name for r in self.readings)

    def on(self, instrument: str, role: str | None = None) -> list[Reading]:
        """The readings drawn on ``instrument`` (in ``role``, if given)."""
        return [r for r in self.readings if r.instrument == instrument and role in (None, r.role)]


def primary(state: np.ndarray) -> list[Reading]:
    """The primary flight display's own values, from a catalogue-ordered state."""
    return [
        Reading(name, float(state[INDEX[name]]), BY_NAME[name].unit, instrument, "value", name)
        for name, instrument in PRIMARY.items()
    ]


def task_readings(task: Any, state: np.ndarray, step: int) -> list[Reading]:
    """``task``'s readings at agent ``step`` (the aircraft in catalogue-ordered ``state``):
    the guidance lines it declares (``tasks.guidance``) with their values."""
    lines = task.guidance_lines()
    if not lines:
        return []
    observed = dict(zip(task.observation_names, task.observe(state, step).tolist(), strict=True))
    return [
        Reading(line.name, float(value), line.unit, line.instrument, line.role, line.label)
        for line, value in zip(lines, task.guidance_values(observed), strict=True)
    ]


def display_of(task: Any, state: np.ndarray, step: int, flying: bool = True) -> Display:
    """What the window shows of ``task`` (a bound Task) at agent ``step`` of an episode, the
    aircraft in catalogue-ordered ``state``; only the primary instruments when not
    ``flying`` (before the first episode: no plan, no targets yet)."""
    readings = primary(state)
    if flying:
        readings += task_readings(task, state, step)
    return Display(tuple(readings))
