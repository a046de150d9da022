"""Grades: how well a flown episode went, in an instructor's four words.

A task's judge measures each error its success rule bounds, over the span the rule judges
(``Measure``: the error's worst moment there, or its mean where the rule averages it as in
turbulence, and the tolerance the rule allows), and may add what an instructor grades but no
rule fails (the approach: the bank on final, of the 15 deg a stabilized final allows); each
task's docstring names its measures in its ``Grade:`` sentence. The grade is
``unsatisfactory`` when the verdict is a failure. A success is graded as an instructor grades
a check ride, by how much of its tolerance the worst excursion used: within ``SHARES[0]``
(a quarter) of every tolerance ``excellent``, within ``SHARES[1]`` (half) ``good``, beyond
that ``fair`` (passed). The worst moment grades, not the RMS error: on the approach every
tier of synthetic pilot tracked within about a tenth of the tolerances RMS, so RMS graded the
novice tier, whose worst excursions used a third of the tolerances and more, as excellent as
the expert tier (docs/results/capture.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

GRADES = ("excellent", "good", "fair", "unsatisfactory")  # best first
SHARES = (0.25, 0.5)  # the share of every tolerance within which a success is excellent, good


@dataclass(frozen=True)
class Measure:
    """One error of a flown episode over the judged span: its worst moment (or its mean:
    ``kind``), and its tolerance."""

    name: str
    unit: str
    value: float
    tolerance: float
    kind: str = "worst"

    @property
    def share(self) -> float:
        """The error as a share of the tolerance."""
        return self.value / self.tolerance

    @classmethod
    def of(cls, name: str, unit: str, errors: Any, tolerance: float, mean: bool = False) -> Measure:
        """The measure of ``errors`` (one per step): the worst |error|, or with ``mean`` the
        mean |error| (an empty span measures as NaN)."""
        size = np.abs(np.asarray(errors, dtype=np.float64))
        value = math.nan if not size.size else float(size.mean() if mean else size.max())
        return cls(name, unit, value, float(tolerance), "mean" if mean else "worst")


def grade(success: bool, measures: tuple[Measure, ...] | list[Measure]) -> str:
    """The grade of an episode judged ``success`` with these measures (module docstring)."""
    if not success:
        return GRADES[3]
    worst = max((m.share for m in measures), default=0.0)
    if not math.isfinite(worst):
        return GRADES[2]
    return GRADES[0] if worst <= SHARES[0] else GRADES[1] if worst <= SHARES[1] else GRADES[2]


def said(measures: tuple[Measure, ...] | list[Measure]) -> str:
    """The measures in words: ``glide path 23 ft of 100 (worst)``, ..."""
    return ", ".join(
        f"{m.name} {m.value:.3g} {m.unit} of {m.tolerance:g} ({m.kind})" for m in measures
    )


def rank(value: Any) -> int:
    """A grade's place, best first (0 excellent ... 3 unsatisfactory); -1 for anything else
    (no grade logged: an older log, an ungraded source)."""
    return GRADES.index(value) if value in GRADES else -1
