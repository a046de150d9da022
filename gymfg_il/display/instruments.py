"""Moved to ``gymfg_il.tasks.guidance`` (the instruments a task puts its targets on sit below
the tasks); this path keeps working for now, with a DeprecationWarning."""

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.tasks.guidance")
