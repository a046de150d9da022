"""The paper's Figure 1 for any task: one row per episode; columns for the control signal,
the target against the controlled variable, and the reward."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.evaluation.trace import Trace
from gymfg_il.sim.properties import ACTION_NAMES, BY_NAME

# The surface that mainly drives each controlled variable (Figure 1's "control signal").
PRIMARY_CONTROL = {
    "altitude_ft": 1,
    "pitch_deg": 1,
    "roll_deg": 0,
    "heading_deg": 0,
    "airspeed_kts": 3,
    "beta_deg": 2,
}


def primary_control(variable: str) -> int:
    """The surface drawn for ``variable`` (the elevator for a variable not listed)."""
    return PRIMARY_CONTROL.get(variable, 1)


def drawn(trace: Trace) -> tuple[np.ndarray, np.ndarray]:
    """(target, value) of ``trace`` as a plot draws them: an angle that goes all the way
    round (heading, roll) is unwrapped, so that crossing north is not a jump of 360 degrees
    and the same target is never drawn once at -100 and once at 260; the target is drawn on
    the value's turn (value + error, the error being wrapped to [-180, 180))."""
    var = BY_NAME.get(trace.variable)
    if var is None or var.unit != "deg" or var.high - var.low < 360.0:
        return trace.target, trace.value
    value = np.unwrap(trace.value, period=360.0)
    return np.unwrap(value + trace.error, period=360.0), value


def unit_of(variable: str) -> str:
    """The catalogue's unit of ``variable`` ("" for one it does not hold)."""
    var = BY_NAME.get(variable)
    return var.unit if var is not None else ""


def figure1(episodes: Sequence[Trace], control: int, title: str, path: Path) -> Path:
    """Save the Figure-1 grid of ``episodes`` to ``path`` (PNG) and return the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = len(episodes)
    fig, axes = plt.subplots(rows, 3, figsize=(12, 2.3 * rows + 0.8), squeeze=False, sharex=True)
    for row, ep in zip(axes, episodes, strict=True):
        t = ep.time_s
        var = ep.variable
        row[0].plot(t, ep.actions[:, control], color="tab:blue", lw=1)
        row[0].set_ylabel(f"seed {ep.seed}\n{ACTION_NAMES[control]}")
        target, value = drawn(ep)
        row[1].plot(t, target, color="tab:red", lw=1.2, ls="--", label="target")
        row[1].plot(t, value, color="tab:green", lw=1, label=var)
        row[1].set_ylabel(f"{var.rsplit('_', 1)[0]} ({unit_of(var)})")
        row[2].plot(t, ep.rewards, color="tab:purple", lw=1)
        row[2].set_ylabel("reward")
        if ep.terminated:
            row[1].set_title(f"terminated: {ep.reason}", fontsize=8, color="tab:red")
    axes[0][0].set_title("control signal")
    axes[0][1].set_title(axes[0][1].get_title() or "target vs controlled variable")
    axes[0][1].legend(fontsize=7, loc="best")
    axes[0][2].set_title("reward")
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    return save_figure(fig, title, path)


def save_figure(fig: Any, title: str, path: Path) -> Path:
    """Title, lay out and write ``fig`` to ``path`` (PNG), then free it."""
    import matplotlib.pyplot as plt

    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
