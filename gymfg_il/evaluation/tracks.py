"""Maneuvers flown over the ground, drawn as a pilot briefs them: a ground track (north up,
with the gates or the runway) and a vertical profile, every agent of one seed in one row."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.evaluation.plots import drawn, save_figure
from gymfg_il.evaluation.trace import Trace
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.maneuvers import local_ft
from gymfg_il.units import FT_PER_DEG, FT_PER_NM, wrap_180

COLOURS = ("black", "tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown")


def has_track(trace: Trace) -> bool:
    """Whether the trace is of a maneuver flown over the ground (gates, a runway, a lead)."""
    plan = trace.plan or {}
    return trace.states is not None and any(k in plan for k in ("gates", "threshold", "lead"))


def _origin(plan: Mapping[str, Any]) -> tuple[float, float]:
    point = plan.get("origin") or plan.get("threshold") or plan["lead"][0][:2]
    return float(point[0]), float(point[1])


def _draw_plan(top: Any, side: Any, plan: Mapping[str, Any], origin: tuple[float, float]) -> None:
    import matplotlib.patches as mpatches

    if "lead" in plan:  # the lead's track (lat, lon, altitude, roll, pitch, heading per step)
        lead = np.asarray(plan["lead"])
        north = (lead[:, 0] - origin[0]) * FT_PER_DEG
        east = wrap_180(lead[:, 1] - origin[1]) * FT_PER_DEG * math.cos(math.radians(origin[0]))
        top.plot(east, north, color="tab:red", ls="--", lw=1, label="lead")

    if "gates" in plan:
        for k, (north, east, _) in enumerate(plan["gates"]):
            r = plan["radius_ft"]
            top.add_patch(mpatches.Circle((east, north), r, fill=False, color="tab:red"))
            top.annotate(str(k + 1), (east, north), color="tab:red", fontsize=8)
    if "threshold" in plan:
        c = math.radians(plan["course_deg"])
        back = np.array([0.0, 6.0 * FT_PER_NM])
        top.plot(-back * math.sin(c), -back * math.cos(c), color="tab:red", ls="--", lw=0.8)
        top.plot([0, 6000 * math.sin(c)], [0, 6000 * math.cos(c)], color="tab:gray", lw=3)
        tan = math.tan(math.radians(plan["glide_deg"]))
        x = np.linspace(0, 5 * FT_PER_NM, 50)
        path = plan["threshold_ft"] + np.maximum(plan["decision_height_ft"], x * tan)
        side.plot(x / FT_PER_NM, path, color="tab:red", ls="--", lw=1, label="glide path")
        side.invert_xaxis()


def ground_tracks(
    traces: Mapping[str, Sequence[Trace]], title: str, path: Path, episodes: int = 4
) -> Path:
    """One row per seed: the ground track and the vertical profile of every agent."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(traces)
    rows = min(episodes, len(traces[names[0]]))
    fig, axes = plt.subplots(rows, 2, figsize=(11, 3.6 * rows + 0.6), squeeze=False)
    for r in range(rows):
        top, side = axes[r]
        first = traces[names[0]][r]
        plan = first.plan or {}
        origin = _origin(plan)
        approach = "threshold" in plan
        for colour, name in zip(COLOURS, names, strict=False):
            tr = traces[name][r]
            assert tr.states is not None
            north, east = local_ft(tr.states, origin)
            ok = "ok" if tr.verdict and not tr.terminated else "failed"
            top.plot(east, north, color=colour, lw=1, label=f"{name} ({ok})")
            alt = tr.states[:, INDEX["altitude_ft"]]
            if approach:
                c = math.radians(plan["course_deg"])
                along = -(north * math.cos(c) + east * math.sin(c))
                side.plot(along / FT_PER_NM, alt, color=colour, lw=1)
            else:
                side.plot(np.arange(len(alt)) * tr.dt, alt, color=colour, lw=1)
        if not approach:  # the altitude each step aimed for (the next gate's, ...)
            target, _ = drawn(first)
            side.plot(first.time_s, target, color="tab:red", ls="--", lw=1, label="target")
        _draw_plan(top, side, plan, origin)
        top.set_aspect("equal", adjustable="datalim")
        top.set_ylabel(f"seed {first.seed}\nnorth (ft)")
        top.legend(fontsize=7, loc="best")
        side.set_ylabel("altitude (ft)")
        side.set_xlabel("distance to threshold (NM)" if approach else "time (s)")
    axes[-1][0].set_xlabel("east (ft)")
    axes[0][0].set_title("ground track")
    axes[0][1].set_title("vertical profile")
    return save_figure(fig, title, path)
