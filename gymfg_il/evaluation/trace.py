"""Flying an agent through seeded episodes and keeping what the metrics and plots need."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from gymfg_il.controllers.agent import Agent
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.tasks.library import LevelFlightTask
from gymfg_il.tasks.targets import TargetTask

# The surface that mainly drives each family (the paper's Figure 1 "control signal" column).
PRIMARY_CONTROL = {"altitude": 1, "pitch": 1, "level": 1, "roll": 0, "heading": 0, "airspeed": 3}
CONTROL_NAMES = ("aileron", "elevator", "rudder", "throttle")


@dataclass
class Episode:
    """One flown episode: the target and the controlled variable over time, actions, rewards.

    ``target``, ``value`` and ``error`` have one entry per agent step after the reset (the
    state the step led to); ``actions`` is (steps, 4).
    """

    seed: int
    variable: str
    tolerance: float
    dynamic: bool
    dt: float
    target: np.ndarray
    value: np.ndarray
    error: np.ndarray
    actions: np.ndarray
    rewards: np.ndarray
    terminated: bool
    reason: str | None

    @property
    def time_s(self) -> np.ndarray:
        return (np.arange(len(self.rewards)) + 1) * self.dt

    @property
    def total_return(self) -> float:
        return float(self.rewards.sum())


def task_variable(env: AircraftEnv) -> tuple[str, float, bool]:
    """(controlled variable, tolerance, dynamic) of the env's task."""
    task = env.task
    if isinstance(task, TargetTask):
        return task.family.variable, task.tolerance, task.dynamic
    if isinstance(task, LevelFlightTask):
        return "altitude_ft", task.altitude_tolerance, False
    raise TypeError(f"{type(task).__name__} has no target to evaluate against")


def fly_episode(env: AircraftEnv, agent: Agent, seed: int) -> Episode:
    """Fly ``agent`` for one episode of ``env`` seeded with ``seed``."""
    variable, tolerance, dynamic = task_variable(env)
    names = env.observation_names
    obs, _ = env.reset(seed=seed)
    agent.reset(seed)
    level = isinstance(env.task, LevelFlightTask)
    i_err = names.index("altitude_ft_error" if level else f"{variable}_error")
    i_val = names.index(variable)
    targets, values, errors, actions, rewards = [], [], [], [], []
    terminated, truncated = False, False
    info: dict[str, object] = {}
    while not (terminated or truncated):
        action = np.asarray(agent.act(obs), dtype=np.float64)
        obs, reward, terminated, truncated, info = env.step(action)
        err = float(obs[i_err])
        values.append(float(obs[i_val]))
        errors.append(err)
        targets.append(float(obs[i_val]) + err)
        actions.append(np.clip(action, [-1, -1, -1, 0], 1))
        rewards.append(reward)
    return Episode(
        seed=seed,
        variable=variable,
        tolerance=tolerance,
        dynamic=dynamic,
        dt=env.dt,
        target=np.array(targets),
        value=np.array(values),
        error=np.array(errors),
        actions=np.array(actions),
        rewards=np.array(rewards),
        terminated=bool(terminated),
        reason=str(info["reason"]) if "reason" in info else None,
    )


def fly_episodes(
    env: AircraftEnv,
    agent: Agent,
    seeds: Iterable[int],
    progress: Callable[[], None] | None = None,
) -> list[Episode]:
    """Fly one episode per seed; ``progress`` is called after each."""
    episodes = []
    for seed in seeds:
        episodes.append(fly_episode(env, agent, seed))
        if progress is not None:
            progress()
    return episodes
