"""The options of a solo flight, declared once: ``FlightOptions``.

One aircraft (callsign ``ego``) flying one task, how often its pilot is asked and in what air.
The gymnasium env takes these options as keywords (``AircraftEnv("roll", "f15",
agent_hz=30)``), ``FlightSpec.solo`` builds its spec from them, and every command's config
builds on them (``collect``'s ``CollectConfig``, ``eval``'s ``EvalConfig``; the LeRobot env
config maps its ``--env.*`` fields onto them), so each of ``--aircraft``, ``--task``,
``--dynamic``, ``--episode-time``, ``--agent-hz``, ``--turbulence`` and ``--wind-kt`` is declared
here and nowhere else.

An option left unset (None) takes the flight's default: the flight spec's own (``unset_values``:
c172p, altitude, fixed targets, 10 Hz, still air) and the task's own episode time. ``eval``
reads an unset option as "the policy's own" instead (``evaluation.plan``).

    spec = FlightOptions(task="roll", agent_hz=30).flight()  # = FlightSpec.solo(task="roll", ...)
    FlightOptions.of(spec).given()                           # its options, as keywords
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from gymfg_il.aircraft import Aircraft
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.flight import STILL_AIR, FlightSpec
from gymfg_il.envs.roster import AircraftSpec, TeamSpec
from gymfg_il.errors import ConfigError
from gymfg_il.sim.gusts import GustLevel
from gymfg_il.sim.weather import Turbulence, Weather
from gymfg_il.tasks.library import task_class

# options that describe the aircraft (the rest are the flight's run settings), by the name the
# aircraft's spec gives them
AIRCRAFT_OPTIONS = {
    "aircraft": "model",
    "task": "task",
    "dynamic": "dynamic",
    "task_kwargs": "task_kwargs",
}
WEATHER_OPTIONS = tuple(STILL_AIR)  # turbulence, wind_kt, wind_from_deg, gusts
TASK_OWN_TIME = (
    "the task's own: 90 s for most, 120 for waypoints, 180 for approach (on the c172p; "
    "the turns, waypoints and formation last longer on aircraft that turn slower)"
)


@dataclass
class FlightOptions:
    """The options of a solo flight (see the module docstring); None: the default.

    Attributes:
        aircraft: JSBSim model (c172p, f15, A320, or any other JSBSim ships).
        task: a target task (altitude, roll, pitch, heading, airspeed, sideslip: the rudder's
            task, level) or a maneuver (turn, climb-turn, waypoints, formation, approach).
        dynamic: moving targets instead of fixed ones.
        episode_time_s: seconds per episode; reaching them truncates the episode.
        agent_hz: agent rate in Hz = a dataset's fps, a divisor of 120.
        turbulence: fly in JSBSim's turbulence: none, light, moderate or severe (seeded per
            episode, recorded in the flight spec, so a policy is evaluated in it by default).
        wind_kt: a steady wind from a direction drawn per episode.
        task_kwargs: arguments of the task class (e.g. ``target_range``).
        sim_hz: JSBSim rate in Hz.
        wind_from_deg: where the wind blows from (true; None: drawn per episode).
        trimmed_starts: start in trimmed straight, level flight, or untrimmed (False).
        gusts: seeded gust events to recover from: none, light, moderate or severe (peaks
            of 5-20, 20-35, 35-50 ft/s, 1-4 s long, one every 8-16, 6-12, 4-8 s; drawn
            from each episode's seed, listed in the log and the dataset; ``sim.gusts``).
    """

    aircraft: str | None = None
    task: str | None = None
    dynamic: bool | None = None
    episode_time_s: float | None = field(default=None, metadata={"flag": "--episode-time"})
    agent_hz: int | None = None
    turbulence: Turbulence | None = None
    wind_kt: float | None = None
    task_kwargs: dict[str, Any] | None = None
    sim_hz: int | None = field(default=None, metadata={"cli": False})
    wind_from_deg: float | None = field(default=None, metadata={"cli": False})
    trimmed_starts: bool | None = field(default=None, metadata={"cli": False})
    # a flag of `collect manual` only (a person's recoveries), where the log lists them
    gusts: GustLevel | None = field(default=None, metadata={"cli": False})

    @classmethod
    def of(cls, flight: FlightSpec) -> FlightOptions:
        """The options of a solo flight (every one set)."""
        return cls(**{f.name: getattr(flight, f.name) for f in dataclasses.fields(FlightOptions)})

    def given(self) -> dict[str, Any]:
        """The options that are set, by name."""
        names = [f.name for f in dataclasses.fields(FlightOptions)]
        return {n: getattr(self, n) for n in names if getattr(self, n) is not None}

    def flight(self) -> FlightSpec:
        """The solo flight: the options that are set, the defaults for the rest."""
        given = self.given()
        ego = AircraftSpec(
            callsign="ego",
            **{AIRCRAFT_OPTIONS[k]: given.pop(k) for k in AIRCRAFT_OPTIONS if k in given},
        )
        profile = Aircraft(ego.model, ego.callsign).profile
        given.setdefault(
            "episode_time_s", task_class(ego.task, ego.dynamic).episode_time_for(profile)
        )
        return FlightSpec(teams=(TeamSpec("ego", (ego,)),), **given)

    def env_config(self, views: Mapping[str, Sequence[int]] | None = None) -> EnvConfig:
        """The run settings (rates, weather, starts) as an env config: what a task given as a
        class or an instance rather than by name flies with (``AircraftEnv``)."""
        given = self.given()
        weather = Weather(**{k: given[k] for k in WEATHER_OPTIONS if k in given})
        run = {k: given[k] for k in ("sim_hz", "agent_hz", "trimmed_starts") if k in given}
        return EnvConfig(views=views, weather=weather, **run)


def unset_values() -> dict[str, Any]:
    """What each option is when unset, from the flight spec's own defaults (the episode time
    is the task's own, ``TASK_OWN_TIME``)."""
    aircraft = {f.name: f.default for f in dataclasses.fields(AircraftSpec)}
    run = {f.name: f.default for f in dataclasses.fields(FlightSpec)}
    values = {k: aircraft[v] for k, v in AIRCRAFT_OPTIONS.items() if k != "task_kwargs"}
    values |= {k: run[k] for k in ("agent_hz", "turbulence", "wind_kt", "sim_hz")}
    return values


def options_problem(options: dict[str, Any]) -> ConfigError | None:
    """A clear error for keywords that are not flight options (a typo), or None."""
    known = [f.name for f in dataclasses.fields(FlightOptions)]
    unknown = sorted(set(options) - set(known))
    if not unknown:
        return None
    return ConfigError(f"unknown flight options {unknown}; the options are {', '.join(known)}")
