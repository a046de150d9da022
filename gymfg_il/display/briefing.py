"""What the window says before and after an episode.

The briefing states the task in words: its goal (the first paragraph of the task's
docstring), what counts as success (the docstring's ``Success:`` sentence, or the target
rule of ``tasks.verdicts``), what grades it (the ``Grade:`` sentence, with the shares of
``tasks.grades``) and the time. Nothing is written twice: change a task's docstring
and the briefing follows.

The debrief gives the task's verdict on the flown episode (``tasks.verdicts.EpisodeVerdict``:
a maneuver's judge, or the target rule), its grade (``tasks.grades``), why it ended, the
return and the main error.
"""

from __future__ import annotations

import inspect
import re
import textwrap
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.sim.properties import BY_NAME
from gymfg_il.tasks.grades import GRADES, SHARES, Measure, grade, said
from gymfg_il.tasks.verdicts import HOLD_S, EpisodeVerdict, allowed_error

WIDTH = 84  # characters per line of the window's text panel


def _wrap(text: str) -> list[str]:
    return textwrap.wrap(" ".join(text.split()), WIDTH)


def _success(task: Any) -> str:
    doc = inspect.getdoc(type(task)) or ""
    found = re.search(r"Success:\s*(.*?)(?:\n\s*\n|\n\s*Start|\s*Grade:|\Z)", doc, re.S)
    if found:
        return found.group(1).strip()
    tracked = task.tracked()
    if tracked:
        variable = BY_NAME[tracked["variable"]]
        tolerance = allowed_error(tracked["tolerance"], tracked["dynamic"])
        return (
            f"{variable.description} within {tolerance:g} {variable.unit} of the target over "
            f"the last {HOLD_S:g} s, without crashing or stalling."
        )
    return "fly the whole episode without crashing or stalling."


def briefing(task: Any, episode_time_s: float) -> list[str]:
    """The task in words: goal, success, time (a bound Task)."""
    doc = inspect.getdoc(type(task)) or type(task).__name__
    goal = doc.split("\n\n")[0]
    lines = [f"TASK: {task.name}", *_wrap(goal), *_wrap("Success: " + _success(task))]
    graded = re.search(r"Grade:\s*(.*?)(?:\n\s*\n|\n\s*Start|\Z)", doc, re.S)
    if graded:
        lines += _wrap(
            f"Grade: {graded.group(1).strip()} Excellent when the worst of each stays within "
            f"{SHARES[0]:.0%} of its tolerance, good within {SHARES[1]:.0%}."
        )
    lines.append(f"Time: {episode_time_s:g} s. The targets are the magenta bugs; the panel guides.")
    return lines


@dataclass(frozen=True)
class Debrief:
    """The verdict of one flown episode, its grade (``tasks.grades.GRADES``), and the lines
    that say them."""

    success: bool
    detail: str
    lines: tuple[str, ...]
    grade: str = GRADES[3]


def debrief(
    task: Any,
    states: np.ndarray,
    errors: np.ndarray,
    dt: float,
    ended: str,
    total_return: float,
    gusty: bool = False,
) -> Debrief:
    """``debrief_of`` the episode the bound ``task`` has just flown, given as arrays:
    ``states`` (catalogue order, the reset state first) and ``errors`` (the tracked error
    entry of each step's observation)."""
    judge = getattr(task, "judge", None)
    verdict = EpisodeVerdict.flown(task.describe(), states, errors, dt, gusty, judge)
    return debrief_of(verdict, ended, total_return)


def debrief_of(verdict: EpisodeVerdict, ended: str, total_return: float) -> Debrief:
    """Judge an episode as evaluation does (``tasks.verdicts.EpisodeVerdict``); ``ended``
    says why it ended (``time limit``, ``crashed``, ``ended by the pilot``)."""
    terminated = ended not in ("time limit", "ended by the pilot")
    judged = verdict.judge(ended if terminated else None)
    success = bool(judged is not None and judged.success)
    detail = "" if judged is None else judged.detail
    measures: tuple[Measure, ...] = () if judged is None else judged.measures
    graded = grade(success, measures)
    head = ("SUCCESS: " if success else "FAILED: ") + detail
    steps = len(verdict.errors)  # the steps whose error was tracked
    lines = [*_wrap(head), f"ended: {ended}; return {total_return:.1f}; {steps} steps"]
    lines += _wrap(f"grade: {graded}" + (f" ({said(measures)})" if measures else ""))
    return Debrief(success, detail, tuple(lines), graded)
