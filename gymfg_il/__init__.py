"""GymFG-IL: GymFG's aircraft, teams and tasks on JSBSim with the gymnasium API, and an
imitation-learning toolkit around them.

Importing the package registers the ``GymFG/*-v0`` gymnasium ids.
"""

import warnings

from gymfg_il.envs.registration import register_envs
from gymfg_il.envs.team import Team

__version__ = "0.1.0"
__all__ = ["Team", "__version__"]

# pygame 2.6 imports setuptools' deprecated pkg_resources (pygame/pkgdata.py), whose warning
# then opened every manual run, GUI screenshot and window; only that warning, from that
# module, is silenced
warnings.filterwarnings(
    "ignore", "pkg_resources is deprecated", UserWarning, module=r"pygame\.pkgdata"
)

register_envs()
