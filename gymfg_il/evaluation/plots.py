"""The paper's Figure 1 for any task: one row per episode; columns for the control signal,
the target against the controlled variable, and the reward."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from gymfg_il.evaluation.trace import Trace
from gymfg_il.sim.properties import ACTION_NAMES

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


UNITS = {
    "altitude_ft": "ft",
    "roll_deg": "deg",
    "pitch_deg": "deg",
    "heading_deg": "deg",
    "airspeed_kts": "kt",
}


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
        row[1].plot(t, ep.target, color="tab:red", lw=1.2, ls="--", label="target")
        row[1].plot(t, ep.value, color="tab:green", lw=1, label=var)
        row[1].set_ylabel(f"{var.rsplit('_', 1)[0]} ({UNITS.get(var, '')})")
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
