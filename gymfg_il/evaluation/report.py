"""The comparison table printed by ``python -m gymfg_il.eval``."""

from __future__ import annotations

import math
from collections.abc import Sequence

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


def _share(value: object, what: str) -> str:
    if value is None:
        return f"{what} n/a (the controller's is 0)"
    return f"{what} {float(value):.1%}"  # type: ignore[arg-type]


def ratio_line(row: dict[str, object]) -> str:
    """``policy:P / controller: return 99.7%, success 100.0%`` for one row."""
    return (
        f"{row['agent']} / controller: {_share(row['return_ratio'], 'return')}, "
        f"{_share(row['success_ratio'], 'success')}"
    )
