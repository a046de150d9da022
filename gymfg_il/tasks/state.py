"""State variables as tasks see them: the catalogue and named views of state vectors.

Everything here is declared once in ``gymfg_il.sim.properties``; this module is where task and
reward authors find it.
"""

from gymfg_il.sim.properties import (
    ACTION_NAMES,
    BY_NAME,
    CATALOGUE,
    DEFAULT_OPPONENT_VIEW,
    INDEX,
    NAMES,
    ORIENTATION,
    POSITION,
    StateVar,
    StateView,
    describe,
    indices,
)

__all__ = [
    "ACTION_NAMES",
    "BY_NAME",
    "CATALOGUE",
    "DEFAULT_OPPONENT_VIEW",
    "INDEX",
    "NAMES",
    "ORIENTATION",
    "POSITION",
    "StateVar",
    "StateView",
    "describe",
    "indices",
]
