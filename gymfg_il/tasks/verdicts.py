"""Whether a target was held: the success rule of the target tasks, in one place (evaluation
scores episodes with it, the manual window's debrief states it).

The error must stay within the tolerance through the last ``HOLD_S`` seconds; a moving
target's tolerance is ``TRACKING_FACTOR`` times the static one; in turbulence a gust carries
any aircraft past a calm-air tolerance for a moment, so there the error must average within
the tolerance over those seconds instead. Maneuvers judge themselves (``ManeuverTask.judge``),
by the same token in turbulence (``tasks.maneuvers``).
``judge_flight`` judges any flown episode from its task's record, with the measures its grade
reads (``tasks.grades``): the manual window's debrief and the autopilot's collector use it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from gymfg_il.sim.properties import BY_NAME
from gymfg_il.tasks.grades import Measure

HOLD_S = 10.0
TRACKING_FACTOR = 3.0


def allowed_error(tolerance: float, dynamic: bool) -> float:
    """The error a held target may show: the tolerance, wider for a moving target."""
    return tolerance * (TRACKING_FACTOR if dynamic else 1.0)


def held(
    errors: np.ndarray,
    tolerance: float,
    dynamic: bool,
    dt: float,
    gusty: bool = False,
    hold_s: float = HOLD_S,
) -> bool:
    """Whether ``errors`` (one per agent step) end held within the tolerance."""
    steps = max(1, round(hold_s / dt))
    tail = np.abs(np.asarray(errors))[-steps:]
    if len(tail) < steps:
        return False
    worst = tail.mean() if gusty else tail.max()
    return bool(worst <= allowed_error(tolerance, dynamic))


Judged = tuple[bool | None, str, tuple[Measure, ...]]  # success (None: not judged), words


def judge_flight(
    task: dict[str, Any],
    states: np.ndarray,
    errors: np.ndarray,
    dt: float,
    gusty: bool = False,
    judge: Callable[..., Any] | None = None,
) -> Judged:
    """Judge a flown episode from its task's record (``Task.describe()``): a maneuver by its
    judge (``judge``, else the library task the record names) on ``states`` (catalogue
    order, the reset state first), a target task by the target rule on ``errors`` (the
    tracked error entry of each step's observation), any other task as flown to the end. A
    maneuver whose judge cannot be found (a task of your own, named in a record) is not
    judged: success None."""
    plan = task.get("plan")
    if plan:
        if judge is None:
            from gymfg_il.errors import ConfigError
            from gymfg_il.tasks.library import task_class

            name = str(task.get("task", ""))
            try:
                judge = None if ":" in name else getattr(task_class(name), "judge", None)
            except ConfigError:
                judge = None
            if judge is None:
                return None, "", ()
        verdict = judge(plan, states, dt, gusty)
        return verdict.success, verdict.detail, verdict.measures
    tracked = task.get("tracked")
    if not tracked:
        return True, "flown to the end", ()
    if not len(errors):
        return False, "no step flown", ()
    ok = held(errors, tracked["tolerance"], tracked["dynamic"], dt, gusty)
    last = np.abs(np.asarray(errors)[-max(1, round(HOLD_S / dt)) :])
    variable = BY_NAME[tracked["variable"]]
    allowed = allowed_error(tracked["tolerance"], tracked["dynamic"])
    return (
        ok,
        f"over the last {HOLD_S:g} s the error was {last.mean():.1f} {variable.unit} on "
        f"average, at most {last.max():.1f} {variable.unit}",
        (Measure.of(variable.description, variable.unit, last, allowed, mean=gusty),),
    )
