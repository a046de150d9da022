"""Teams: named groups of aircraft, each with its task (the paper's ``Team`` interface)."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from gymfg_il.aircraft import Aircraft
from gymfg_il.errors import ConfigError, DuplicateNameError, join_problems
from gymfg_il.names import name_problem
from gymfg_il.tasks.base import Task

TaskSpec = type[Task] | Task | Callable[[], Task]


def build_task(spec: TaskSpec, where: str) -> Task:
    """A fresh Task from a roster entry: a Task class, a configured instance (copied), or a
    zero-argument factory such as ``functools.partial(ReachStaticTargetRollTask, target=30)``."""
    if isinstance(spec, Task):
        return copy.deepcopy(spec)
    if callable(spec):
        task = spec()
        if isinstance(task, Task):
            return task
        raise ConfigError(f"{where}: the task factory returned {task!r}, not a Task")
    raise ConfigError(
        f"{where}: {spec!r} is not a task; give a Task class (DummyTask), an instance, or a "
        "zero-argument factory"
    )


@dataclass
class Team:
    """A named team of aircraft, each flying its own task.

    Args:
        name: the team's name, unique in its simulation.
        roster: ``[(aircraft, TaskClass), ...]``; callsigns unique within the simulation.
            A task may be a Task class, a configured instance or a zero-argument factory.
        reward_function_targets: ``{aircraft: [other aircraft, ...]}``: whose states each
            aircraft's reward also receives (teammates in full, opponents as the environment
            lets them be seen). Aircraft not listed use no other states.
        episode_time_s: episode length in seconds (90 by default); the smallest among the
            teams of a simulation ends the episode for all.

    Example (the paper's listing)::

        red = Team(name="red", roster=[(f15("red-one"), DummyTask), (f15("red-two"), DummyTask)],
                   reward_function_targets={f15("red-one"): [f15("red-two")], f15("red-two"): []})
    """

    name: str
    roster: Sequence[tuple[Aircraft, TaskSpec]]
    reward_function_targets: dict[Aircraft, list[Aircraft]] = field(default_factory=dict)
    episode_time_s: float = 90.0

    def __post_init__(self) -> None:
        problems: list[str] = []
        if not isinstance(self.name, str) or not self.name.strip():
            problems.append(f"name must be a non-empty string, got {self.name!r}")
        elif bad := name_problem(self.name, "team name"):  # it reaches logs and the wire
            problems.append(bad)
        roster = list(self.roster) if isinstance(self.roster, (list, tuple)) else None
        if not roster:
            problems.append(
                f"roster must be a non-empty list of (aircraft, task) pairs, got {self.roster!r}"
            )
            roster = []
        seen: set[str] = set()
        for i, entry in enumerate(roster):
            if not (isinstance(entry, tuple) and len(entry) == 2):
                problems.append(f"roster[{i}]={entry!r} is not an (aircraft, task) pair")
                continue
            aircraft, task = entry
            if not isinstance(aircraft, Aircraft):
                problems.append(f"roster[{i}][0]={aircraft!r} is not an Aircraft (use c172p(...))")
                continue
            if aircraft.callsign in seen:
                raise DuplicateNameError(
                    f"team {self.name!r} lists callsign {aircraft.callsign!r} twice; give every "
                    "aircraft its own callsign"
                )
            seen.add(aircraft.callsign)
            if not (isinstance(task, Task) or callable(task)):
                problems.append(f"roster[{i}][1]={task!r} is not a Task class, instance or factory")
        members = {a for a, _ in roster if isinstance(a, Aircraft)} if not problems else set()
        if not isinstance(self.reward_function_targets, dict):
            problems.append("reward_function_targets must be a dict {aircraft: [aircraft, ...]}")
        else:
            for owner, targets in self.reward_function_targets.items():
                if members and owner not in members:
                    problems.append(
                        f"reward_function_targets names {owner!r}, which is not in the roster"
                    )
                if not isinstance(targets, (list, tuple)) or not all(
                    isinstance(t, Aircraft) for t in targets
                ):
                    problems.append(f"reward targets of {owner!r} must be a list of Aircraft")
                elif owner in targets:
                    problems.append(f"{owner.callsign!r} lists itself as a reward target")
        t = self.episode_time_s
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t) or t <= 0:
            problems.append(f"episode_time_s must be a positive number of seconds, got {t!r}")
        if problems:
            raise ConfigError(join_problems(f"Team {self.name!r:.72}", problems))
        self.roster = roster

    @property
    def aircraft(self) -> list[Aircraft]:
        return [a for a, _ in self.roster]

    @property
    def callsigns(self) -> list[str]:
        return [a.callsign for a, _ in self.roster]

    def targets_of(self, aircraft: Aircraft) -> list[Aircraft]:
        return list(self.reward_function_targets.get(aircraft, []))


def check_unique(teams: Sequence[Team]) -> None:
    """Team names and callsigns must be unique across a simulation."""
    names: set[str] = set()
    callsigns: dict[str, str] = {}
    for team in teams:
        if not isinstance(team, Team):
            raise ConfigError(f"{team!r} is not a Team")
        if team.name in names:
            raise DuplicateNameError(
                f"two teams are named {team.name!r}; team names must be unique in a simulation"
            )
        names.add(team.name)
        for callsign in team.callsigns:
            if callsign in callsigns:
                raise DuplicateNameError(
                    f"callsign {callsign!r} is used by team {callsigns[callsign]!r} and team "
                    f"{team.name!r}; callsigns must be unique in a simulation"
                )
            callsigns[callsign] = team.name
