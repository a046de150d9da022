"""The JSBSim layer: property catalogue, initial conditions, rates and the per-aircraft wrapper."""

from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import (
    ACTION_NAMES,
    CATALOGUE,
    DEFAULT_OPPONENT_VIEW,
    INDEX,
    NAMES,
    StateVar,
    StateView,
)
from gymfg_il.sim.simulation import Simulation
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ, substeps

__all__ = [
    "ACTION_NAMES",
    "CATALOGUE",
    "DEFAULT_AGENT_HZ",
    "DEFAULT_OPPONENT_VIEW",
    "DEFAULT_SIM_HZ",
    "INDEX",
    "NAMES",
    "InitialConditions",
    "Simulation",
    "StateVar",
    "StateView",
    "substeps",
]
