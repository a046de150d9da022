"""Environments: the offline env (paper loop), gymnasium and PettingZoo adapters, scenarios,
and the flight spec that describes what any of them flies.

Modules: ``team`` (Team), ``world`` (the lockstep of every aircraft), ``config`` (EnvConfig),
``offline`` (OfflineEnv), ``single`` (AircraftEnv, gymnasium), ``multiagent`` (the PettingZoo
ParallelEnv), ``flight`` (FlightSpec), ``options`` (FlightOptions: the options of a solo
flight, which the gymnasium env and every command's config build on), ``roster`` (its aircraft
and teams), ``scenarios`` (joint starts), ``actions`` (the action contract), ``registration``
(gymnasium ids). A world's FlightGear views are ``gymfg_il.flightgear.display``.
"""

from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.flight import AircraftSpec, FlightSpec, TeamSpec
from gymfg_il.envs.multiagent import GymFGParallelEnv, parallel_env
from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.envs.options import FlightOptions
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import World

__all__ = [
    "AircraftEnv",
    "AircraftSpec",
    "EnvConfig",
    "FlightOptions",
    "FlightSpec",
    "GymFGParallelEnv",
    "OfflineEnv",
    "Team",
    "TeamSpec",
    "World",
    "parallel_env",
]
