"""Registered gymnasium ids: one per task family, everything else a ``make`` keyword.

``gymnasium.make("GymFG/Altitude-v0", aircraft="f15", dynamic=True,
task_kwargs={"target_range": (-500, 500)})``.
"""

from __future__ import annotations

import gymnasium as gym

ENTRY_POINT = "gymfg_il.envs.single:AircraftEnv"
IDS: dict[str, str] = {
    "GymFG/Altitude-v0": "altitude",
    "GymFG/Roll-v0": "roll",
    "GymFG/Pitch-v0": "pitch",
    "GymFG/Heading-v0": "heading",
    "GymFG/Airspeed-v0": "airspeed",
    "GymFG/Sideslip-v0": "sideslip",
    "GymFG/LevelFlight-v0": "level",
    "GymFG/Dummy-v0": "dummy",
    "GymFG/Turn-v0": "turn",
    "GymFG/ClimbTurn-v0": "climb-turn",
    "GymFG/Waypoints-v0": "waypoints",
    "GymFG/Formation-v0": "formation",
    "GymFG/Approach-v0": "approach",
}


def register_envs() -> None:
    """Register every id once (importing ``gymfg_il`` calls this)."""
    for env_id, family in IDS.items():
        if env_id not in gym.registry:
            gym.register(env_id, entry_point=ENTRY_POINT, kwargs={"task": family})
