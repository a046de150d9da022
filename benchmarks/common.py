"""What every benchmark module shares: the row, timing in paired rounds, and the printer.

This VM's speed swings 20-30% within minutes. A ratio is therefore measured in paired rounds
(each candidate round right beside its reference round) and reported as the median of the
per-round ratios: a slow spell then lands on both sides of a pair instead of on one side of a
best-of.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Row:
    """One benchmark figure.

    ``detail`` lines are printed above the row (the references measured beside it); ``extra``
    goes into the JSON row beside name, value, unit, target and higher_is_better.
    """

    name: str
    value: float
    unit: str
    target: float | None = None
    higher_is_better: bool = True
    detail: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)
    at_most: bool = False  # a lower-is-better target the value may equal (<=, not <)

    def json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "value": self.value,
            "unit": self.unit,
            "target": self.target,
            "higher_is_better": self.higher_is_better,
            **self.extra,
        }

    def verdict(self) -> str:
        if self.target is None:
            return "(reported)"
        if self.higher_is_better:
            ok, sign = self.value >= self.target, ">="
        elif self.at_most:
            ok, sign = self.value <= self.target, "<="
        else:
            ok, sign = self.value < self.target, "<"
        return f"(target {sign} {self.target:,g}: {'met' if ok else 'NOT MET'})"


def rate(fn: Callable[[int], None], steps: int) -> float:
    """Steps per second of one call ``fn(steps)``."""
    t0 = time.perf_counter()
    fn(steps)
    return steps / (time.perf_counter() - t0)


def paired(
    candidate: Callable[[int], None], reference: Callable[[int], None], steps: int, rounds: int
) -> dict[str, Any]:
    """Rates of ``candidate`` and ``reference`` in paired rounds (the side that goes first
    alternates), and the median of the per-round ratios candidate / reference."""
    ratios, cand, ref = [], [], []
    for i in range(rounds):
        if i % 2:
            r, c = rate(reference, steps), rate(candidate, steps)
        else:
            c, r = rate(candidate, steps), rate(reference, steps)
        cand.append(c)
        ref.append(r)
        ratios.append(c / r)
    return {
        "ratio": statistics.median(ratios),
        "ratios": ratios,
        "candidate": statistics.median(cand),
        "reference": statistics.median(ref),
    }


def print_rows(rows: list[Row]) -> None:
    """The one printer: each row's references, then the row with its target."""
    for row in rows:
        for line in row.detail:
            print(f"  {line}")
        value = f"{row.value:,.3f}" if abs(row.value) < 100 else f"{row.value:,.0f}"
        print(f"{row.name:<34} {value:>12} {row.unit:<9} {row.verdict()}\n", flush=True)
