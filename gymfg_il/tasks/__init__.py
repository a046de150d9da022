"""Tasks: each aircraft's observation, reward, termination and start state, and what the rest
of the toolkit knows of a task, which the task declares itself: its guidance lines, its
tracked target and its expert's structure.

Submodules: ``base`` (Task), ``targets`` (static/dynamic target machinery), ``library`` (the
named tasks), ``maneuvers``, ``courses``, ``approach`` and ``formation`` (the maneuvers),
``paths`` (tasks of your own named by import path, and the trust a record needs to name
one), ``rewards`` (RewardContext and shaping), ``guidance`` (what a task shows a pilot),
``experts`` (the structure of a task's expert), ``verdicts`` (``EpisodeVerdict``: one
accumulator judges every episode) and ``grades``, ``scenery`` (what a camera draws),
``geometry``, ``orientation`` and ``state`` (the state-variable catalogue and StateView).
"""

from gymfg_il.tasks.base import FLIGHT_VARS, Task
from gymfg_il.tasks.library import (
    TASK_FAMILIES,
    DummyTask,
    LevelFlightTask,
    ReachDynamicTargetAirspeedTask,
    ReachDynamicTargetAltitudeTask,
    ReachDynamicTargetHeadingTask,
    ReachDynamicTargetPitchTask,
    ReachDynamicTargetRollTask,
    ReachDynamicTargetSideslipTask,
    ReachStaticTargetAirspeedTask,
    ReachStaticTargetAltitudeTask,
    ReachStaticTargetHeadingTask,
    ReachStaticTargetPitchTask,
    ReachStaticTargetRollTask,
    ReachStaticTargetSideslipTask,
    task_class,
    task_reference,
)
from gymfg_il.tasks.rewards import RewardContext, RewardFn
from gymfg_il.tasks.targets import FAMILIES, TargetFamily, TargetTask

__all__ = [
    "FAMILIES",
    "FLIGHT_VARS",
    "TASK_FAMILIES",
    "DummyTask",
    "LevelFlightTask",
    "ReachDynamicTargetAirspeedTask",
    "ReachDynamicTargetAltitudeTask",
    "ReachDynamicTargetHeadingTask",
    "ReachDynamicTargetPitchTask",
    "ReachDynamicTargetRollTask",
    "ReachDynamicTargetSideslipTask",
    "ReachStaticTargetAirspeedTask",
    "ReachStaticTargetAltitudeTask",
    "ReachStaticTargetHeadingTask",
    "ReachStaticTargetPitchTask",
    "ReachStaticTargetRollTask",
    "ReachStaticTargetSideslipTask",
    "RewardContext",
    "RewardFn",
    "TargetFamily",
    "TargetTask",
    "Task",
    "task_class",
    "task_reference",
]
