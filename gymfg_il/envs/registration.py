"""Registered gymnasium ids: one per task family, everything else a ``make`` keyword.

``gymnasium.make("GymFG/Altitude-v0", aircraft="f15", dynamic=True,
task_kwargs={"target_range": (-500, 500)})``.

The ids follow the task registry (``tasks.library.TASK_FAMILIES``): a family's name in
CamelCase (``climb-turn`` is ``GymFG/ClimbTurn-v0``), ``level`` is ``GymFG/LevelFlight-v0``.
"""

from __future__ import annotations

import gymnasium as gym

from gymfg_il.tasks.library import TASK_FAMILIES

ENTRY_POINT = "gymfg_il.envs.single:AircraftEnv"
ID_NAMES = {"level": "LevelFlight"}  # where an id says more than the family's short name


def env_id(family: str) -> str:
    """The gymnasium id of a task family."""
    name = ID_NAMES.get(family) or "".join(w.capitalize() for w in family.split("-"))
    return f"GymFG/{name}-v0"


IDS: dict[str, str] = {env_id(family): family for family in TASK_FAMILIES}


def register_envs() -> None:
    """Register every id once (importing ``gymfg_il`` calls this)."""
    for name, family in IDS.items():
        if name not in gym.registry:
            gym.register(name, entry_point=ENTRY_POINT, kwargs={"task": family})
