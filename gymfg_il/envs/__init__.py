"""Environments: the offline env (paper loop), gymnasium and PettingZoo adapters, scenarios."""

from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.envs.parallel import GymFGParallelEnv, parallel_env
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import EnvConfig, World

__all__ = [
    "AircraftEnv",
    "EnvConfig",
    "GymFGParallelEnv",
    "OfflineEnv",
    "Team",
    "World",
    "parallel_env",
]
