"""Who flies in a flight spec, as plain data: each aircraft (``AircraftSpec``: model,
callsign, task and the task's options) and each team (``TeamSpec``), and the conversion of
task options to and from JSON-able values (``plain``, ``live``)."""

from __future__ import annotations

import dataclasses
import functools
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from gymfg_il.aircraft import resolve_model
from gymfg_il.errors import ConfigError, UntrustedTaskError
from gymfg_il.names import check_name
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks.base import Task
from gymfg_il.tasks.library import TASK_FAMILIES, task_class
from gymfg_il.tasks.paths import record_task_problem

UNBUILDABLE = "python:"  # marks a recorded value that cannot be rebuilt from the record


class FrozenDict(dict[str, Any]):
    """A dict a flight spec holds: it cannot be changed in place (``FlightSpec.replace``
    makes a changed copy), it hashes by content, and it pickles and JSON-encodes as a dict."""

    def _readonly(self, *args: object, **kwargs: object) -> None:
        raise TypeError("a flight spec cannot be changed in place; use FlightSpec.replace")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _readonly  # type: ignore[assignment]
    __ior__ = _readonly  # type: ignore[assignment]

    def __hash__(self) -> int:  # type: ignore[override]
        return hash(json.dumps(self, sort_keys=True, default=str))

    def __reduce__(self) -> tuple[type, tuple[dict[str, Any]]]:
        return (FrozenDict, (dict(self),))


def plain(value: Any) -> Any:
    """A task option as immutable JSON-able data: sequences as tuples, mappings as
    ``FrozenDict``, ``InitialConditions`` as a tagged mapping, and anything that is not data
    (a reward function) as ``"python:<name>"``."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, InitialConditions):
        return FrozenDict(initial_conditions=FrozenDict(dataclasses.asdict(value)))
    if isinstance(value, (list, tuple)):
        return tuple(plain(v) for v in value)
    if isinstance(value, Mapping):
        return FrozenDict({str(k): plain(v) for k, v in value.items()})
    if hasattr(value, "item") and callable(value.item):  # a numpy scalar
        return plain(value.item())
    name = getattr(value, "__qualname__", type(value).__qualname__)
    return f"{UNBUILDABLE}{getattr(value, '__module__', '?')}.{name}"


def live(value: Any) -> Any:
    """The inverse of ``plain`` for what can be rebuilt (plain dicts, tuples, objects)."""
    if isinstance(value, Mapping):
        if set(value) == {"initial_conditions"}:
            return InitialConditions(**value["initial_conditions"])
        return {k: live(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return tuple(live(v) for v in value)
    return value


def unbuildable(value: Any) -> list[str]:
    if isinstance(value, str):
        return [value] if value.startswith(UNBUILDABLE) else []
    if isinstance(value, Mapping):
        return [u for v in value.values() for u in unbuildable(v)]
    if isinstance(value, (list, tuple)):
        return [u for v in value for u in unbuildable(v)]
    return []


@dataclass(frozen=True)
class AircraftSpec:
    """One aircraft of a flight.

    Attributes:
        model: JSBSim model (``c172p``, ``f15``, ``A320``, ...; case-insensitive).
        callsign: its name in the simulation.
        task: a task family (``altitude``, ``roll``, ``pitch``, ``heading``, ``airspeed``,
            ``level``, ``dummy``) or a task class's import path ``package.module:ClassName``.
        dynamic: the family's moving-target variant.
        task_kwargs: the task's options as plain data (e.g. ``{"target_range": [-500, 500]}``).
    """

    model: str = "c172p"
    callsign: str = "ego"
    task: str = "altitude"
    dynamic: bool = False
    task_kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "model", resolve_model(self.model))
        check_name(self.callsign, "callsign")
        if not isinstance(self.task_kwargs, Mapping):
            raise ConfigError(f"task_kwargs must be a mapping, got {self.task_kwargs!r}")
        object.__setattr__(self, "task_kwargs", plain(dict(self.task_kwargs)))
        object.__setattr__(self, "dynamic", bool(self.dynamic))
        library = self.task in TASK_FAMILIES or ":" not in str(self.task)
        if library and not unbuildable(self.task_kwargs):
            self.task_factory()()  # a library task is checked now: bad input fails at once

    @property
    def label(self) -> str:
        """The task's short name: ``altitude``, ``roll-dynamic``, ..."""
        return f"{self.task}-dynamic" if self.dynamic else self.task

    def task_factory(self) -> Callable[[], Task]:
        """A zero-argument factory of this aircraft's task (a Team roster entry)."""
        bad = unbuildable(self.task_kwargs)
        if bad:
            raise ConfigError(
                f"the task of {self.callsign!r} was flown with {bad}, which a record cannot "
                "rebuild; pass the teams (or the env) that flew it"
            )
        return functools.partial(task_class(self.task, self.dynamic), **live(self.task_kwargs))

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": self.model,
            "callsign": self.callsign,
            "task": self.task,
            "dynamic": self.dynamic,
            "task_kwargs": self.task_kwargs,
        }


@dataclass(frozen=True)
class TeamSpec:
    """A team of a flight: its name, its aircraft, and whose states each one's reward sees
    (``reward_targets``: callsign -> ((target callsign, target model), ...))."""

    name: str
    roster: tuple[AircraftSpec, ...]
    reward_targets: Mapping[str, tuple[tuple[str, str], ...]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_name(self.name, "team name")
        object.__setattr__(self, "roster", tuple(self.roster))
        if not all(isinstance(a, AircraftSpec) for a in self.roster):
            raise ConfigError(f"team {self.name!r}: its roster must hold AircraftSpec entries")
        targets = {
            str(owner): tuple((str(c), str(m)) for c, m in found)
            for owner, found in dict(self.reward_targets).items()
        }
        object.__setattr__(self, "reward_targets", FrozenDict(targets))
        members = {a.callsign for a in self.roster}
        strangers = sorted(set(targets) - members)
        if strangers:
            raise ConfigError(
                f"team {self.name!r}: reward_targets name {strangers}, which are not in its roster"
            )

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "roster": [a.to_dict() for a in self.roster],
            "reward_targets": {
                owner: [{"callsign": c, "model": m} for c, m in targets]
                for owner, targets in self.reward_targets.items()
            },
        }


def teams_from_record(records: Any) -> tuple[TeamSpec, ...]:
    """The teams a flight spec record lists (``FlightSpec.to_dict()["teams"]``), read from a
    file: a task named by import path whose module nobody imported is refused
    (``UntrustedTaskError``), as building it would run code the file chose."""
    try:
        teams = tuple(
            TeamSpec(
                t["name"],
                tuple(AircraftSpec(**a) for a in t["roster"]),
                {
                    owner: tuple((x["callsign"], x["model"]) for x in targets)
                    for owner, targets in t.get("reward_targets", {}).items()
                },
            )
            for t in records
        )
    except (KeyError, TypeError) as err:
        raise ConfigError(f"flight spec record is malformed ({err!r})") from None
    for team in teams:
        for aircraft in team.roster:
            problem = record_task_problem(aircraft.task)
            if problem is not None:
                raise UntrustedTaskError(problem)
    return teams
