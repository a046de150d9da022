"""Flying agents: the one rollout loop, its step records, the agents it flies, and seeded
episodes on worker processes.

Modules: ``records`` (Step, Trajectory, Episode), ``loop`` (Rollout), ``agents`` (AgentSpec:
the task's controller or a policy checkpoint), ``seeded`` (fly_many: one episode per seed, in
seed order, on ``workers`` processes).
"""

from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.rollout.records import Episode, Step, Tick, Trajectory
from gymfg_il.rollout.seeded import fly_many, fly_seed

__all__ = [
    "AgentSpec",
    "Episode",
    "Rollout",
    "Step",
    "Tick",
    "Trajectory",
    "fly_many",
    "fly_seed",
]
