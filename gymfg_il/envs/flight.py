"""What is flown, as one serializable record: ``FlightSpec``.

A flight spec names every aircraft (JSBSim model, callsign, task and the task's options), the
teams they fly in and whose states their rewards see, and the run's settings: agent and
simulation rates, episode time, opponent view and joint start (scenario). It is written whole
into every MCAP session record, every dataset episode, every policy's ``config.json`` and every
eval row, and read back whole by replay, eval, DAgger and training, so nothing about a flight
is retyped or guessed from a name.

    spec = FlightSpec.solo("c172p", "roll", agent_hz=30)     # one aircraft ("ego")
    env = spec.make_env()                                    # the gymnasium env it describes
    FlightSpec.from_dict(spec.to_dict()) == spec             # a round trip is exact

A team run's spec comes from its world (``FlightSpec.of_world``). Tasks of your own are named
by import path (``package.module:ClassName``); options that are not plain data (a reward
lambda) are recorded by name and make the spec describe, but not rebuild, the flight
(``rebuild_problems``).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from gymfg_il.aircraft import Aircraft
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.roster import AircraftSpec, TeamSpec, plain, teams_from_record, unbuildable
from gymfg_il.envs.scenarios import Scenario, scenario_from_record, scenario_record
from gymfg_il.envs.team import Team
from gymfg_il.errors import ConfigError, GymFGError, join_problems
from gymfg_il.sim.gusts import GustLevel
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, indices
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ, episode_steps, substeps
from gymfg_il.sim.weather import Turbulence, Weather
from gymfg_il.tasks.library import task_class, task_reference

if TYPE_CHECKING:
    from gymfg_il.envs.single import AircraftEnv
    from gymfg_il.envs.world import SimPool, World

__all__ = ["STILL_AIR", "AircraftSpec", "FlightSpec", "TeamSpec"]
SPEC_VERSION = 1
# the weather fields of a flight in still air: flights equal once these are set differ only in
# their weather
STILL_AIR: dict[str, Any] = {
    "turbulence": "none", "wind_kt": 0.0, "wind_from_deg": None, "gusts": "none"
}  # fmt: skip


def _default_teams() -> tuple[TeamSpec, ...]:
    return (TeamSpec("ego", (AircraftSpec(),)),)


@dataclass(frozen=True)
class FlightSpec:
    """Everything that decides what a flight is (see the module docstring).

    Attributes:
        teams: the teams and their aircraft; a solo flight is one team, ``ego``, of one
            aircraft, ``ego`` (``FlightSpec.solo``).
        agent_hz: agent rate (Hz), an exact divisor of ``sim_hz``; a dataset's fps.
        sim_hz: JSBSim rate (Hz).
        episode_time_s: episode length in seconds; reaching it truncates the episode.
        opponent_view: what an aircraft sees of other teams' aircraft.
        scenario: a joint start as a record (``envs.scenarios.scenario_record``), or None.
        turbulence: none, light, moderate or severe (JSBSim's Dryden turbulence, seeded per
            episode; ``sim.weather``).
        wind_kt: a steady wind (knots).
        wind_from_deg: where the wind blows from (true; None: drawn per episode).
        gusts: none, light, moderate or severe: discrete gusts, seeded per episode
            (``sim.gusts``); recorded only when there are some.
        trimmed_starts: the tasks' and scenarios' starts are trimmed straight, level flight
            (``sim.initial.InitialConditions.trimmed``). A record without it was flown before
            trimmed starts existed and reads as False, so its episodes replay as flown.
    """

    teams: tuple[TeamSpec, ...] = field(default_factory=_default_teams)
    agent_hz: int = DEFAULT_AGENT_HZ
    sim_hz: int = DEFAULT_SIM_HZ
    episode_time_s: float = 90.0
    opponent_view: tuple[str, ...] = DEFAULT_OPPONENT_VIEW
    scenario: Mapping[str, Any] | None = None
    turbulence: Turbulence = "none"
    wind_kt: float = 0.0
    wind_from_deg: float | None = None
    trimmed_starts: bool = True
    gusts: GustLevel = "none"

    def __post_init__(self) -> None:
        problems: list[str] = []
        errors: list[GymFGError] = []
        t = self.episode_time_s
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t) or t <= 0:
            problems.append(f"episode_time_s={t!r} must be a positive number of seconds")
        for check in (
            lambda: self.weather,
            lambda: substeps(self.sim_hz, self.agent_hz),
            lambda: not problems and episode_steps(self.episode_time_s, self.agent_hz),
            lambda: indices(tuple(self.opponent_view)),
        ):
            try:
                check()
            except GymFGError as err:
                errors.append(err)
                problems.append(str(err))
        object.__setattr__(self, "opponent_view", tuple(self.opponent_view))
        object.__setattr__(self, "teams", tuple(self.teams))
        if self.scenario is not None:
            object.__setattr__(self, "scenario", plain(dict(self.scenario)))
        view = self.opponent_view
        if len(set(view)) != len(view):
            problems.append(f"opponent_view lists a variable twice: {view}")
        if not self.teams:
            problems.append("a flight needs at least one team")
        names = [t.name for t in self.teams]
        callsigns = [a.callsign for t in self.teams for a in t.roster]
        for what, values in (("team names", names), ("callsigns", callsigns)):
            twice = sorted({v for v in values if values.count(v) > 1})
            if twice:
                problems.append(f"{what} {twice} appear twice; each must be unique")
        if any(not t.roster for t in self.teams):
            problems.append("every team needs at least one aircraft")
        if len(problems) == 1 and errors:
            raise errors[0]  # its own type (a RateError stays one)
        if problems:
            raise ConfigError(join_problems("flight spec", problems))

    # -- solo flights ------------------------------------------------------------------
    @classmethod
    def solo(cls, aircraft: str = "c172p", task: str = "altitude", **options: Any) -> FlightSpec:
        """One aircraft, callsign ``ego``, flying one task (what the gymnasium env flies);
        ``options`` are the other ``FlightOptions`` (``dynamic``, ``task_kwargs``,
        ``agent_hz``, ``sim_hz``, ``episode_time_s``: by default the task's own, 90 s for most,
        longer for the maneuvers that need it; ``turbulence``, ``wind_kt``, ``wind_from_deg``,
        ``trimmed_starts``)."""
        from gymfg_il.envs.options import FlightOptions, options_problem

        problem = options_problem(options)
        if problem is not None:
            raise problem
        return FlightOptions(aircraft=aircraft, task=task, **options).flight()

    @property
    def is_solo(self) -> bool:
        return len(self.teams) == 1 and len(self.teams[0].roster) == 1

    @property
    def solo_aircraft(self) -> AircraftSpec:
        """The one aircraft of a solo flight; a clear error for a team flight."""
        if not self.is_solo:
            raise ConfigError(
                f"this flight has {len(self.aircraft_specs)} aircraft in {len(self.teams)} "
                "team(s); this needs a solo flight (FlightSpec.solo) or one aircraft chosen "
                "with .for_callsign(...)"
            )
        return self.teams[0].roster[0]

    @property
    def aircraft(self) -> str:
        return self.solo_aircraft.model

    @property
    def task(self) -> str:
        return self.solo_aircraft.task

    @property
    def dynamic(self) -> bool:
        return self.solo_aircraft.dynamic

    @property
    def task_kwargs(self) -> Mapping[str, Any]:
        return self.solo_aircraft.task_kwargs

    @property
    def task_label(self) -> str:
        return self.solo_aircraft.label

    @property
    def weather(self) -> Weather:
        return Weather(self.turbulence, self.wind_kt, self.wind_from_deg, self.gusts)

    @property
    def gusty(self) -> bool:
        """Whether the flight is in turbulence or gusts (``Weather.gusty``): its episodes are
        judged allowing for them (``tasks.verdicts``)."""
        return self.weather.gusty

    @property
    def aircraft_specs(self) -> list[AircraftSpec]:
        return [a for t in self.teams for a in t.roster]

    def replace(self, **changes: Any) -> FlightSpec:
        """A copy with run settings (``agent_hz``, ``episode_time_s``, ...) and, for a solo
        flight, the aircraft's fields (``aircraft``, ``task``, ``dynamic``, ``task_kwargs``)
        changed."""
        mine = {"aircraft": "model", "task": "task", "dynamic": "dynamic"}
        mine["task_kwargs"] = "task_kwargs"
        solo = {mine[k]: changes.pop(k) for k in list(changes) if k in mine}
        spec = dataclasses.replace(self, **changes)
        if solo:
            ego = dataclasses.replace(self.solo_aircraft, **solo)
            spec = dataclasses.replace(
                spec, teams=(dataclasses.replace(self.teams[0], roster=(ego,)),)
            )
        return spec

    def for_callsign(self, callsign: str) -> FlightSpec:
        """The solo flight of one aircraft of this flight (its model and task, these run
        settings): what a policy trained on that aircraft's episodes flies on its own."""
        for a in self.aircraft_specs:
            if a.callsign == callsign:
                ego = dataclasses.replace(a, callsign="ego")
                return dataclasses.replace(self, teams=(TeamSpec("ego", (ego,)),), scenario=None)
        raise ConfigError(f"this flight has no aircraft {callsign!r}")

    # -- records -------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "version": SPEC_VERSION,
            "teams": [t.to_dict() for t in self.teams],
            "agent_hz": self.agent_hz,
            "sim_hz": self.sim_hz,
            "episode_time_s": self.episode_time_s,
            "opponent_view": list(self.opponent_view),
            "scenario": self.scenario,
            "turbulence": self.turbulence,
            "wind_kt": self.wind_kt,
            "wind_from_deg": self.wind_from_deg,
            "trimmed_starts": self.trimmed_starts,
        } | ({"gusts": self.gusts} if self.gusts != "none" else {})  # records before gusts

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FlightSpec:
        """The spec a ``to_dict`` record describes; a clear error for anything else."""
        try:
            return cls._from_dict(data)
        except (TypeError, ValueError, AttributeError) as err:
            if isinstance(err, GymFGError):
                raise
            raise ConfigError(f"flight spec record is malformed ({err})") from None

    @classmethod
    def _from_dict(cls, data: Mapping[str, Any]) -> FlightSpec:
        if not isinstance(data, Mapping) or "teams" not in data:
            raise ConfigError(f"not a flight spec record (no 'teams'): {str(data)[:200]}")
        version = data.get("version", SPEC_VERSION)
        if version != SPEC_VERSION:
            raise ConfigError(
                f"flight spec version {version} is not {SPEC_VERSION}; upgrade gymfg-il"
            )
        known = {f.name for f in dataclasses.fields(cls)} | {"version"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ConfigError(f"flight spec record has unknown keys {unknown}")
        teams = teams_from_record(data["teams"])
        settings = {k: data[k] for k in known - {"version", "teams"} if k in data}
        settings.setdefault("trimmed_starts", False)  # recorded before trimmed starts existed
        if "opponent_view" in settings:
            settings["opponent_view"] = tuple(settings["opponent_view"])
        return cls(teams, **settings)

    @classmethod
    def from_json(cls, text: str) -> FlightSpec:
        try:
            return cls.from_dict(json.loads(text))
        except json.JSONDecodeError as err:
            raise ConfigError(f"flight spec is not valid JSON: {err}") from None

    @classmethod
    def of_world(cls, world: World) -> FlightSpec:
        """The spec of a running world (its teams as built, its settings)."""
        teams = []
        for team in world.teams:
            roster = []
            for slot in world.team_slots[team.name]:
                name, dynamic = task_reference(type(slot.task))
                kwargs = plain(slot.task.options)
                roster.append(
                    AircraftSpec(slot.aircraft.model, slot.callsign, name, dynamic, kwargs)
                )
            targets = {
                owner.callsign: tuple((t.callsign, t.model) for t in found)
                for owner, found in team.reward_function_targets.items()
            }
            teams.append(TeamSpec(team.name, tuple(roster), targets))
        config = world.config
        weather = config.weather
        return cls(
            teams=tuple(teams),
            agent_hz=config.agent_hz,
            sim_hz=config.sim_hz,
            episode_time_s=world.max_steps / config.agent_hz,
            opponent_view=config.opponent_view,
            scenario=scenario_record(config.scenario),
            turbulence=weather.turbulence,
            wind_kt=weather.wind_kt,
            wind_from_deg=weather.wind_from_deg,
            trimmed_starts=config.trimmed_starts,
            gusts=weather.gusts,
        )

    def rebuild_problems(self) -> list[str]:
        """What keeps this record from building its flight again (empty: nothing)."""
        problems = [
            f"{a.callsign}: option {bad}"
            for a in self.aircraft_specs
            for bad in unbuildable(a.task_kwargs)
        ]
        for a in self.aircraft_specs:
            try:
                task_class(a.task, a.dynamic)
            except ConfigError as err:
                problems.append(f"{a.callsign}: {err}")
        if self.scenario is not None:
            try:
                scenario_from_record(self.scenario)
            except ConfigError as err:
                problems.append(f"scenario: {err}")
        return problems

    def external_callsigns(self) -> list[str]:
        """Reward targets outside this flight: aircraft an online team sees from the server."""
        inside = {a.callsign for a in self.aircraft_specs}
        return sorted(
            {c for t in self.teams for found in t.reward_targets.values() for c, _ in found}
            - inside
        )

    # -- building ------------------------------------------------------------------------
    def build_teams(self) -> list[Team]:
        """The runtime ``Team`` objects this spec describes."""
        models = {a.callsign: a.model for a in self.aircraft_specs}
        teams = []
        for t in self.teams:
            roster = [(Aircraft(a.model, a.callsign), a.task_factory()) for a in t.roster]
            targets = {
                Aircraft(models[owner], owner): [Aircraft(m, c) for c, m in found]
                for owner, found in t.reward_targets.items()
            }
            teams.append(Team(t.name, roster, targets, episode_time_s=self.episode_time_s))
        return teams

    def env_config(
        self,
        views: Mapping[str, Any] | None = None,
        traffic: Mapping[str, Any] | None = None,
        scenario: Scenario | None = None,
    ) -> EnvConfig:
        """The environment settings (``scenario`` replaces a recorded one of your own)."""
        return EnvConfig(
            sim_hz=self.sim_hz,
            agent_hz=self.agent_hz,
            opponent_view=self.opponent_view,
            scenario=scenario if scenario is not None else scenario_from_record(self.scenario),
            views=views,
            traffic=traffic,
            weather=self.weather,
            trimmed_starts=self.trimmed_starts,
        )

    def make_world(
        self,
        pool: SimPool | None = None,
        *,
        teams: list[Team] | None = None,
        scenario: Scenario | None = None,
        external_targets: bool = False,
    ) -> World:
        """The world this spec describes (``teams``/``scenario``: the objects that flew it,
        where the record cannot rebuild them)."""
        from gymfg_il.envs.world import World

        config = self.env_config(scenario=scenario)
        external = external_targets or bool(self.external_callsigns())
        return World(teams or self.build_teams(), config, pool, external)

    def make_env(self, views: list[int] | None = None) -> AircraftEnv:
        """The gymnasium env of a solo flight."""
        from gymfg_il.envs.single import AircraftEnv

        return AircraftEnv.from_flight(self, views=views)
