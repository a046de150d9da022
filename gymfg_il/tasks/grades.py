"""Grades: how well a flown episode went, in an instructor's four words.

A task's judge measures each error its success rule bounds, over the span the rule judges
(``Measure``: the error's RMS there and the tolerance the rule allows; each task's docstring
names its measures in its ``Grade:`` sentence). The grade is ``unsatisfactory`` when the
verdict is a failure. A success is graded by the largest share of its tolerance that any
error used, RMS: within ``SHARES[0]`` (a quarter) ``excellent``, within ``SHARES[1]`` (half)
``good``, beyond that ``fair``. The RMS, not the worst moment, grades because a success has
already kept the worst moment within the tolerance, and simulator studies of pilots score
tracking (localizer, glide slope, airspeed) by RMS deviation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

GRADES = ("excellent", "good", "fair", "unsatisfactory")  # best first
SHARES = (0.25, 0.5)  # the RMS share of a tolerance within which a success is excellent, good


@dataclass(frozen=True)
class Measure:
    """One error of a flown episode: its RMS over the judged span, and its tolerance."""

    name: str
    unit: str
    rms: float
    tolerance: float

    @property
    def share(self) -> float:
        """The RMS error as a share of the tolerance."""
        return self.rms / self.tolerance

    @classmethod
    def of(cls, name: str, unit: str, errors: Any, tolerance: float) -> Measure:
        """The measure of ``errors`` (one per step; an empty span measures as NaN)."""
        errors = np.asarray(errors, dtype=np.float64)
        rms = float(np.sqrt(np.mean(errors**2))) if errors.size else math.nan
        return cls(name, unit, rms, float(tolerance))


def grade(success: bool, measures: tuple[Measure, ...] | list[Measure]) -> str:
    """The grade of an episode judged ``success`` with these measures (module docstring)."""
    if not success:
        return GRADES[3]
    worst = max((m.share for m in measures), default=0.0)
    if not math.isfinite(worst):
        return GRADES[2]
    return GRADES[0] if worst <= SHARES[0] else GRADES[1] if worst <= SHARES[1] else GRADES[2]


def said(measures: tuple[Measure, ...] | list[Measure]) -> str:
    """The measures in words: ``glide path 23 ft rms of 100``, ..."""
    return ", ".join(f"{m.name} {m.rms:.3g} {m.unit} rms of {m.tolerance:g}" for m in measures)


def rank(value: Any) -> int:
    """A grade's place, best first (0 excellent ... 3 unsatisfactory); -1 for anything else
    (no grade logged: an older log, an ungraded source)."""
    return GRADES.index(value) if value in GRADES else -1
