"""GymFG-IL: GymFG's aircraft, teams and tasks on JSBSim with the gymnasium API, and an
imitation-learning toolkit around them.

Importing the package registers the ``GymFG/*-v0`` gymnasium ids.
"""

from gymfg_il.envs.registration import register_envs
from gymfg_il.envs.team import Team

__version__ = "0.1.0"
__all__ = ["Team", "__version__"]

register_envs()
