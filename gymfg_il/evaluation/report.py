"""The comparison table printed by ``python -m gymfg_il.eval``."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

COLUMNS = (
    ("agent", "agent", "{}"),
    ("mean_return", "return", "{:.1f}"),
    ("std_return", "± std", "{:.1f}"),
    ("success_rate", "success", "{:.0%}"),
    ("time_to_target_s", "t→target s", "{:.1f}"),
    ("steady_state_error", "ss error", "{:.2f}"),
    ("overshoot", "overshoot", "{:.1f}"),
    ("control_effort", "effort", "{:.3f}"),
    ("smoothness", "Δaction", "{:.4f}"),
    ("terminated", "crashed", "{}"),
)


def _cell(fmt: str, value: object) -> str:
    if isinstance(value, float) and math.isnan(value):
        return "-"
    return fmt.format(value)


def table(rows: Sequence[dict[str, object]]) -> str:
    """A plain-text table, one row per agent."""
    cells = [[title for _, title, _ in COLUMNS]]
    for row in rows:
        cells.append([_cell(fmt, row[key]) for key, _, fmt in COLUMNS])
    widths = [max(len(r[i]) for r in cells) for i in range(len(COLUMNS))]
    lines = ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in cells]
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join(lines)


# (score, its share's key in a row, its name in words)
SHARES = (("mean_return", "return_ratio", "return"), ("success_rate", "success_ratio", "success"))


def shares(row: Mapping[str, Any], reference: Mapping[str, Any]) -> dict[str, float | None]:
    """The mean return and success rate of ``row`` as shares of ``reference``'s, by the keys
    ``return_ratio`` and ``success_ratio``; None where the reference's is zero."""
    found: dict[str, float | None] = {}
    for key, ratio, _ in SHARES:
        ref, value = float(reference[key]), float(row[key])
        found[ratio] = value / ref if ref else None
    return found


def ratio_line(row: Mapping[str, Any], reference: Mapping[str, Any] | None = None) -> str:
    """``policy:P / controller: return 99.7%, success 100.0% (success rates 94% and 94%)``:
    a row's scores as shares of the controller's (the row's own ratios), or of another
    ``reference`` row's; beside the share of success, both success rates (where the
    reference is given), so that a share above 100% never reads as a rate."""
    against = "controller" if reference is None else str(reference["agent"])
    values = row if reference is None else shares(row, reference)
    parts = []
    for _, ratio, what in SHARES:
        value = values[ratio]
        shown = f"n/a (the {against}'s is 0)" if value is None else f"{float(value):.1%}"
        parts.append(f"{what} {shown}")
    rates = ""
    if reference is not None:
        mine, theirs = float(row["success_rate"]), float(reference["success_rate"])
        rates = f" (success rates {mine:.0%} and {theirs:.0%})"
    return f"{row['agent']} / {against}: {', '.join(parts)}{rates}"
