"""What a flight leaves behind: a ``Step`` per aircraft per agent step, gathered into one
``Trajectory`` per aircraft and an ``Episode`` per reset.

The recorder writes these, the metrics score them, DAgger and the manual session produce them
through the same loop (``rollout.loop.Rollout``), so every consumer sees the same fields.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gymfg_il.envs.roster import plain


def reset_record(options: Mapping[str, Any] | None, solo: str | None = None) -> dict[str, Any]:
    """Reset options as a log records them (what replay needs to start the same episode):
    ``initial_conditions`` per callsign (``solo``: the callsign of a gymnasium env's one
    aircraft, whose option is a bare ``InitialConditions``) and a fixed ``target``."""
    out: dict[str, Any] = {}
    if not options:
        return out
    ics = options.get("initial_conditions")
    if ics is not None:
        if solo is not None and not isinstance(ics, Mapping):
            ics = {solo: ics}
        out["initial_conditions"] = {str(c): plain(ic) for c, ic in ics.items()}
    if options.get("target") is not None:
        out["target"] = float(options["target"])
    return out


@dataclass(slots=True)
class Step:
    """One aircraft's agent step.

    Attributes:
        callsign, team: whose step it is.
        step: agent steps since the reset (1 = the first).
        observation: the task observation the action was chosen from (float32).
        action: what was flown: the pilot's action plus any noise, clipped to the contract.
        label: the demonstrator's action for that observation (clipped; the pilot's own
            clean action when nobody else labels).
        reward: the step's reward.
        state: the full catalogue state after the step (float64).
        terminated: the aircraft crashed, stalled or left its envelope at this step.
        truncated: the episode reached its time limit (or its server ended it) at this step.
        intervention: a person flew this step while an assistant was ready to.
        reason: why it terminated, if it did.
    """

    callsign: str
    team: str
    step: int
    observation: np.ndarray
    action: np.ndarray
    label: np.ndarray
    reward: float
    state: np.ndarray
    terminated: bool
    truncated: bool
    intervention: bool = False
    reason: str | None = None


@dataclass(slots=True)
class OpponentView:
    """What one team saw of the other teams' aircraft after a step."""

    callsigns: list[str]
    names: tuple[str, ...]
    values: np.ndarray  # (len(callsigns), len(names)) float64


@dataclass(slots=True)
class Tick:
    """One agent step of the whole flight: every aircraft that flew it, and each team's view."""

    step: int
    steps: list[Step]
    views: dict[str, OpponentView] = field(default_factory=dict)
    done: bool = False
    truncated: bool = False  # the episode reached its time limit (or its server ended it)


@dataclass
class Start:
    """An aircraft at the reset: its task (``Task.describe()``), target and state."""

    callsign: str
    team: str
    model: str
    task: dict[str, Any]
    target: float | None
    state: np.ndarray
    observation: np.ndarray


@dataclass
class Trajectory:
    """One aircraft's episode as arrays, one row per step (``Step``'s fields)."""

    start: Start
    observations: np.ndarray
    final_observation: np.ndarray
    actions: np.ndarray
    labels: np.ndarray
    rewards: np.ndarray
    states: np.ndarray
    interventions: np.ndarray
    terminated: bool
    reason: str | None
    truncated: bool = False  # its flight was cut short when the episode ended

    @property
    def callsign(self) -> str:
        return self.start.callsign

    @property
    def next_observations(self) -> np.ndarray:
        """The observation after each step (what the metrics score)."""
        if not len(self.observations):
            return self.observations
        return np.vstack([self.observations[1:], self.final_observation[None]])

    @property
    def total_return(self) -> float:
        return float(self.rewards.sum())

    def __len__(self) -> int:
        return len(self.rewards)


@dataclass
class Episode:
    """One reset's flight: a trajectory per aircraft (in simulation order) and, for teams,
    what each team saw of the others at every step."""

    seed: int
    dt: float
    trajectories: dict[str, Trajectory]
    views: dict[str, list[OpponentView]] = field(default_factory=dict)
    truncated: bool = False
    options: dict[str, Any] = field(default_factory=dict)  # reset options (reset_record)

    @property
    def solo(self) -> Trajectory:
        """The trajectory of a one-aircraft episode."""
        if len(self.trajectories) != 1:
            raise ValueError(f"this episode has {len(self.trajectories)} aircraft, not one")
        return next(iter(self.trajectories.values()))

    @property
    def outcome(self) -> str:
        """``time limit``, or why the (last) aircraft stopped."""
        if self.truncated:
            return "time limit"
        reasons = [t.reason for t in self.trajectories.values() if t.reason]
        return reasons[-1] if reasons else "terminated"

    # one-aircraft conveniences (evaluation, tests)
    @property
    def rewards(self) -> np.ndarray:
        return self.solo.rewards

    @property
    def actions(self) -> np.ndarray:
        return self.solo.actions

    @property
    def total_return(self) -> float:
        return sum(t.total_return for t in self.trajectories.values())

    @property
    def steps(self) -> int:
        return sum(len(t) for t in self.trajectories.values())


class EpisodeBuilder:
    """Gathers ticks into an ``Episode``."""

    def __init__(
        self, seed: int, dt: float, starts: list[Start], options: dict[str, Any] | None = None
    ) -> None:
        self.seed, self.dt, self.starts, self.options = seed, dt, starts, options or {}
        self.steps: dict[str, list[Step]] = {s.callsign: [] for s in starts}
        self.views: dict[str, list[OpponentView]] = {}
        self.final: dict[str, np.ndarray] = {s.callsign: s.observation for s in starts}
        self.truncated = False

    def add(self, tick: Tick, observations: dict[str, np.ndarray]) -> None:
        """Take a tick and the observations after it."""
        for step in tick.steps:
            self.steps[step.callsign].append(step)
        self.truncated = self.truncated or tick.truncated
        for team, view in tick.views.items():
            self.views.setdefault(team, []).append(view)
        self.final.update(observations)

    def episode(self) -> Episode:
        trajectories = {}
        for start in self.starts:
            steps = self.steps[start.callsign]
            last = steps[-1] if steps else None
            dim = len(start.observation)
            trajectories[start.callsign] = Trajectory(
                start=start,
                observations=np.array([s.observation for s in steps], np.float32).reshape(-1, dim),
                final_observation=self.final[start.callsign],
                actions=np.array([s.action for s in steps], np.float64).reshape(-1, 4),
                labels=np.array([s.label for s in steps], np.float64).reshape(-1, 4),
                rewards=np.array([s.reward for s in steps], np.float64),
                states=np.array([s.state for s in steps], np.float64).reshape(
                    len(steps), len(start.state)
                ),
                interventions=np.array([s.intervention for s in steps], bool),
                terminated=bool(last and last.terminated),
                reason=last.reason if last else None,
                truncated=bool(last and last.truncated),
            )
        return Episode(self.seed, self.dt, trajectories, self.views, self.truncated, self.options)
