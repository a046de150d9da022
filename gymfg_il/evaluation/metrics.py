"""Scores of flown episodes: return, success, time to target, steady-state error, overshoot,
control effort and smoothness.

Definitions (per episode, then averaged over episodes):

- success: the aircraft did not terminate and the episode's verdict passed
  (``tasks.verdicts.EpisodeVerdict``: for a maneuver, the task's own judge of the flown
  states; for the target tasks, the error held within the tolerance through the last 10 s,
  three times the tolerance for a moving target, on the mean error in turbulence). A trace
  made by hand, without a verdict, is held to the target rule over ``hold_s``.
- time_to_target_s: first time ``|error| <= tolerance`` (NaN if never; averaged over the
  episodes that reached it).
- steady_state_error: mean ``|error|`` over the last ``hold_s`` seconds.
- overshoot: how far the variable went past the target, against the direction of the
  initial error (static targets; 0 for dynamic ones), in the variable's units.
- control_effort: mean over steps of the mean |aileron, elevator, rudder|.
- smoothness: mean over steps of the mean |change| of the three surfaces (lower is smoother).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from gymfg_il.evaluation.trace import Trace
from gymfg_il.tasks.verdicts import HOLD_S, held


@dataclass
class EpisodeScore:
    seed: int
    total_return: float
    success: bool
    time_to_target_s: float
    steady_state_error: float
    overshoot: float
    control_effort: float
    smoothness: float
    terminated: bool
    detail: str = ""  # a maneuver's judgement in words


def score_episode(ep: Trace, hold_s: float = HOLD_S) -> EpisodeScore:
    abs_err = np.abs(ep.error)
    hold = max(1, round(hold_s / ep.dt))
    tail = abs_err[-hold:]
    reached = np.flatnonzero(abs_err <= ep.tolerance)
    overshoot = 0.0
    if not ep.dynamic and len(ep.error):
        direction = math.copysign(1.0, ep.error[0]) if ep.error[0] else 0.0
        overshoot = float(max(0.0, (-direction * ep.error).max()))
    surfaces = ep.actions[:, :3] if len(ep.actions) else np.zeros((1, 3))
    changes = np.abs(np.diff(surfaces, axis=0)).mean() if len(surfaces) > 1 else 0.0
    return EpisodeScore(
        seed=ep.seed,
        total_return=ep.total_return,
        success=bool(
            not ep.terminated
            and (
                ep.verdict
                if ep.verdict is not None
                else held(ep.error, ep.tolerance, ep.dynamic, ep.dt, ep.gusty, hold_s)
            )
        ),
        time_to_target_s=float((reached[0] + 1) * ep.dt) if len(reached) else math.nan,
        steady_state_error=float(tail.mean()) if len(tail) else math.nan,
        overshoot=overshoot,
        control_effort=float(np.abs(surfaces).mean()),
        smoothness=float(changes),
        terminated=ep.terminated,
        detail=f"{ep.reason}" if ep.terminated else ep.detail,
    )


def _nanmean(values: list[float]) -> float:
    finite = [v for v in values if not math.isnan(v)]
    return float(np.mean(finite)) if finite else math.nan


def summarize(
    agent: str, task: str, aircraft: str, episodes: list[Trace], hold_s: float = HOLD_S
) -> dict[str, object]:
    """One row of the comparison table (the ``--json`` schema plus extra metrics)."""
    scores = [score_episode(ep, hold_s) for ep in episodes]
    returns = np.array([s.total_return for s in scores])
    return {
        "agent": agent,
        "task": task,
        "aircraft": aircraft,
        "episodes": len(scores),
        "seeds": [s.seed for s in scores],
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),
        "success_rate": float(np.mean([s.success for s in scores])),
        "time_to_target_s": _nanmean([s.time_to_target_s for s in scores]),
        "steady_state_error": _nanmean([s.steady_state_error for s in scores]),
        "overshoot": float(np.mean([s.overshoot for s in scores])),
        "control_effort": float(np.mean([s.control_effort for s in scores])),
        "smoothness": float(np.mean([s.smoothness for s in scores])),
        "terminated": int(sum(s.terminated for s in scores)),
        "per_episode": [asdict(s) for s in scores],
    }
