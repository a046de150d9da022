"""The controlled variable of a flown episode over time: what the metrics and plots read.

A ``Trace`` is taken from a rollout ``Episode`` (``trace_of``): the task says which variable
it brings to a target and which observation entry holds target minus value
(``Task.tracked()``), and the observation after each step gives both. The trace keeps the
episode's verdict (``tasks.verdicts.EpisodeVerdict``: a maneuver's judge on the flown states,
or the target rule on the error).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.rollout.records import Episode
from gymfg_il.tasks.verdicts import EpisodeVerdict


@dataclass
class Trace:
    """One flown episode: the target and the controlled variable over time, actions, rewards.

    ``target``, ``value`` and ``error`` have one entry per agent step after the reset (the
    state the step led to); ``actions`` is (steps, 4).
    """

    seed: int
    variable: str
    tolerance: float
    dynamic: bool
    dt: float
    target: np.ndarray
    value: np.ndarray
    error: np.ndarray
    actions: np.ndarray
    rewards: np.ndarray
    terminated: bool
    reason: str | None
    gusty: bool = False  # flown in turbulence: success is judged on the mean error
    # the task's verdict on what was flown, whatever ended it (``tasks.verdicts``; None in a
    # trace made by hand: ``score_episode`` applies the target rule), and a maneuver's words
    verdict: bool | None = None
    detail: str = ""
    # the catalogue states from the reset on (maneuvers: for ground tracks and profiles)
    states: np.ndarray | None = None
    plan: dict[str, Any] | None = None

    @property
    def time_s(self) -> np.ndarray:
        return (np.arange(len(self.rewards)) + 1) * self.dt

    @property
    def total_return(self) -> float:
        return float(self.rewards.sum())


def trace_of(episode: Episode, callsign: str | None = None, gusty: bool = False) -> Trace:
    """The trace of one aircraft of ``episode`` (the only one, unless ``callsign``);
    ``gusty``: it was flown in turbulence."""
    t = episode.solo if callsign is None else episode.trajectories[callsign]
    return make_trace(
        t.start.task,
        episode.seed,
        episode.dt,
        t.next_observations,
        t.actions,
        t.rewards,
        t.terminated,
        t.reason,
        np.vstack([t.start.state[None], t.states]),
        gusty,
    )


def make_trace(
    task: dict[str, Any],
    seed: int,
    dt: float,
    next_observations: np.ndarray,
    actions: np.ndarray,
    rewards: np.ndarray,
    terminated: bool,
    reason: str | None,
    states: np.ndarray,
    gusty: bool = False,
) -> Trace:
    """The trace of one aircraft's flight: ``task`` is its ``Task.describe()``, ``states``
    the catalogue states from the reset on (the start, then one per step)."""
    tracked = task.get("tracked")
    if not tracked:
        raise ConfigError(f"task {task.get('task')!r} has no target to evaluate against")
    names = list(task["observation"])
    after = np.asarray(next_observations, dtype=np.float64).reshape(len(rewards), len(names))
    value = after[:, names.index(tracked["variable"])]
    error = after[:, names.index(tracked["error"])]
    plan, judge = task.get("plan"), None
    if plan is not None:  # the task the flight names, a task of your own included
        from gymfg_il.tasks.library import task_class

        judge = task_class(task["task"]).judge  # type: ignore[attr-defined]
    judged = EpisodeVerdict.flown(task, states, error, dt, gusty, judge).judge()
    verdict = None if judged is None else judged.success
    # a target task's rows have no words (its figures say it)
    detail = judged.detail if judged is not None and plan is not None else ""
    return Trace(
        seed=seed,
        variable=tracked["variable"],
        tolerance=float(tracked["tolerance"]),
        dynamic=bool(tracked["dynamic"]),
        dt=dt,
        target=value + error,
        value=value,
        error=error,
        actions=np.asarray(actions),
        rewards=np.asarray(rewards),
        terminated=terminated,
        reason=reason,
        gusty=gusty,
        verdict=verdict,
        detail=detail,
        states=states if plan is not None else None,
        plan=plan,
    )
