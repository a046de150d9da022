"""Whether an episode succeeded: the one accumulator every caller judges with
(``EpisodeVerdict``), and the success rule of the target tasks.

``EpisodeVerdict`` takes one episode's flown states and its task's tracked error, step by
step (``add``) or all at once (``flown``), and judges it (``judge``). The cockpit's recorder
(its debrief), the collector's session (each episode's end record), PPO's success bonus and
``eval``'s traces all judge through it, so a flight gets one verdict wherever it is judged;
the synthetic pilot's takeover gate reads the same tracked error (``TrackedError``).

The rule: a maneuver judges itself from the flown states (``ManeuverTask.judge``, by its
own token in turbulence: ``tasks.maneuvers``); a target task's error must stay within the
tolerance through the last ``HOLD_S`` seconds, a moving target's tolerance being
``TRACKING_FACTOR`` times the static one, and in turbulence (``FlightSpec.gusty``), where a
gust carries any aircraft past a calm-air tolerance for a moment, the error must average
within the tolerance over those seconds instead; any other task is judged flown to the end.
An episode that terminated (crashed, stalled, ...) failed, whatever it flew.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.sim.properties import BY_NAME
from gymfg_il.tasks.grades import Measure
from gymfg_il.tasks.maneuvers import Verdict

HOLD_S = 10.0
TRACKING_FACTOR = 3.0

# a maneuver's judge: (plan, states, dt, gusty) -> Verdict (``ManeuverTask.judge``)
JudgeFn = Callable[..., Verdict]


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


@dataclass(frozen=True)
class TrackedError:
    """The one variable a task brings to a target (``Task.tracked()``), as its observation
    carries it: the catalogue ``variable``, the ``error`` entry (target minus value) at
    index ``at``, the ``tolerance`` within which it counts as reached, whether the target
    moves (``dynamic``)."""

    variable: str
    error: str
    at: int
    tolerance: float
    dynamic: bool

    @classmethod
    def of(cls, task: Mapping[str, Any]) -> TrackedError | None:
        """From a task's record (``Task.describe()``); None for a task without a target (or
        whose observation lacks its error entry)."""
        tracked = task.get("tracked") or {}
        names = list(task.get("observation", []))
        if tracked.get("error") not in names:
            return None
        return cls(
            tracked["variable"],
            tracked["error"],
            names.index(tracked["error"]),
            float(tracked.get("tolerance", 0.0)),
            bool(tracked.get("dynamic", False)),
        )

    def __call__(self, observation: Any) -> float:
        """The error in one observation."""
        return float(observation[self.at])

    def column(self, observations: np.ndarray) -> np.ndarray:
        """The error in each of ``observations`` (rows), in their own dtype."""
        return np.asarray(observations)[:, self.at]


def _library_judge(name: str) -> JudgeFn | None:
    """The judge of the library's task ``name``; None for a task the library does not know
    (a task of your own named in a record is not imported for a verdict: ``tasks.paths``)."""
    from gymfg_il.errors import ConfigError
    from gymfg_il.tasks.library import task_class

    if ":" in name:
        return None
    try:
        return getattr(task_class(name), "judge", None)
    except ConfigError:
        return None


class EpisodeVerdict:
    """One episode's flown states and tracked errors, and its judgement (module docstring).

    Args:
        task: the task's record (``Task.describe()``, taken once the episode was reset: a
            maneuver's plan is drawn then).
        dt: seconds per agent step.
        gusty: flown in turbulence (``FlightSpec.gusty``).
        judge: a maneuver's judge; None: the judge of the library task the record names.

    ``start(state)`` takes the reset state, ``add(state, observation)`` each step's state
    and the observation after it; ``judge()`` gives the ``Verdict`` (None: a maneuver whose
    judge cannot be found, not judged).
    """

    def __init__(
        self,
        task: Mapping[str, Any],
        dt: float,
        gusty: bool = False,
        judge: JudgeFn | None = None,
    ) -> None:
        self.task, self.dt, self.gusty, self._judge = dict(task), dt, gusty, judge
        self.tracked = TrackedError.of(task)
        self._states: list[np.ndarray] = []
        self._errors: list[Any] = []  # floats, or an observation column's own scalars

    @classmethod
    def of(cls, task: Any, dt: float, gusty: bool = False) -> EpisodeVerdict:
        """For the episode a bound ``task`` has just been reset for: its record now and its
        own judge (a task of your own included)."""
        return cls(task.describe(), dt, gusty, getattr(task, "judge", None))

    @classmethod
    def flown(
        cls,
        task: Mapping[str, Any],
        states: np.ndarray,
        errors: np.ndarray,
        dt: float,
        gusty: bool = False,
        judge: JudgeFn | None = None,
    ) -> EpisodeVerdict:
        """For an episode already flown: ``states`` (catalogue order, the reset state first)
        and ``errors``, the tracked error after each step (``TrackedError.column``; judged
        in the dtype the caller's observations hold them)."""
        verdict = cls(task, dt, gusty, judge)
        verdict._states, verdict._errors = list(states), list(np.asarray(errors))
        return verdict

    def start(self, state: np.ndarray) -> None:
        """The episode's reset state."""
        self._states, self._errors = [state.copy()], []

    def add(self, state: np.ndarray, observation: Any) -> None:
        """One flown step: the state it led to and the observation after it."""
        self._states.append(state.copy())
        if self.tracked is not None:
            self._errors.append(self.tracked(observation))

    @property
    def states(self) -> np.ndarray:
        """The flown states, the reset state first."""
        return np.array(self._states)

    @property
    def errors(self) -> np.ndarray:
        """The tracked error after each step (empty for a task without a target)."""
        return np.asarray(self._errors)

    @property
    def steps(self) -> int:
        return max(0, len(self._states) - 1)

    def judge(self, ended: str | None = None) -> Verdict | None:
        """The verdict: ``ended`` says why the episode terminated (``crashed``, ...), which
        fails it; None judges what was flown by the task's rule (module docstring)."""
        if ended is not None:
            return Verdict(False, ended)
        plan = self.task.get("plan")
        if plan:
            judge = self._judge or _library_judge(str(self.task.get("task", "")))
            return None if judge is None else judge(plan, self.states, self.dt, self.gusty)
        tracked = self.task.get("tracked")
        if not tracked:
            return Verdict(True, "flown to the end")
        errors = self.errors
        if not len(errors):
            return Verdict(False, "no step flown")
        return self._held(errors, tracked)

    def _held(self, errors: np.ndarray, tracked: Mapping[str, Any]) -> Verdict:
        ok = held(errors, tracked["tolerance"], tracked["dynamic"], self.dt, self.gusty)
        last = np.abs(errors[-max(1, round(HOLD_S / self.dt)) :])
        variable = BY_NAME[tracked["variable"]]
        allowed = allowed_error(tracked["tolerance"], tracked["dynamic"])
        gusty = self.gusty
        return Verdict(
            ok,
            f"over the last {HOLD_S:g} s the error was {last.mean():.1f} {variable.unit} on "
            f"average, at most {last.max():.1f} {variable.unit}",
            (Measure.of(variable.description, variable.unit, last, allowed, mean=gusty),),
        )


Judged = tuple[bool | None, str, tuple[Measure, ...]]  # success (None: not judged), words


def judge_flight(
    task: dict[str, Any],
    states: np.ndarray,
    errors: np.ndarray,
    dt: float,
    gusty: bool = False,
    judge: JudgeFn | None = None,
) -> Judged:
    """Deprecated: ``EpisodeVerdict`` judges an episode (its states and tracked errors, here
    given as arrays) for every caller."""
    warnings.warn(
        "tasks.verdicts.judge_flight is deprecated: judge with EpisodeVerdict",
        DeprecationWarning,
        stacklevel=2,
    )
    found = EpisodeVerdict.flown(task, states, errors, dt, gusty, judge).judge()
    return (None, "", ()) if found is None else (found.success, found.detail, found.measures)
