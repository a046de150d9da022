"""Moved to ``gymfg_il.tasks.guidance``: each task declares its guidance lines itself
(``Task.guidance_lines()``, ``Task.guidance_values(observed)``); this path keeps working for
now, with a DeprecationWarning."""

from gymfg_il.moved import forward

_DECLARED = "each task declares its own: Task.guidance_lines() and Task.guidance_values(observed)"
__getattr__ = forward(
    __name__,
    "gymfg_il.tasks.guidance",
    gone={
        "guide": _DECLARED,
        "Values": _DECLARED,
        "MANEUVERS": _DECLARED,
        "TURN": "TurnTask.guidance",
        "CLIMB_TURN": "ClimbTurnTask.guidance",
        "WAYPOINTS": "WaypointsTask.guidance",
        "FORMATION": "FormationTask.guidance",
        "APPROACH": "ApproachTask.guidance",
    },
)
