"""The envs PPO trains in: the policy's own flight, taking actions in the policy's normalised
units (``normalized_actions``), its reward what ``rl.reward`` composes, its observation
extended by the policy's memory where it has one (``Remembering``) (``make_env``); and the
vector env that samples them (``training_envs``): stable-baselines3's own, or the grouped
sampler (``rl.grouped``).
"""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.rl import reward


def normalized_actions(env: gym.Env, mean: np.ndarray, std: np.ndarray) -> gym.Env:
    """``env`` taking actions in a policy's normalised units (``(action - mean) / std`` of its
    dataset; a spread under 1e-6 counts as 1): it receives ``action * std + mean``. The
    action space is the contract's box in those units, so PPO's clipping keeps every action
    inside the contract."""
    return NormalizedActions(env, mean, std)


class NormalizedActions(gym.ActionWrapper):
    """``normalized_actions``' wrapper (a class: picklable, unlike a lambda). An action of
    four numbers is taken back to the env's units in Python floats, the same doubles as
    numpy's ``action * std + mean`` at half its cost (this runs at every training step)."""

    def __init__(self, env: gym.Env, mean: np.ndarray, std: np.ndarray) -> None:
        super().__init__(env)
        box = env.action_space
        assert isinstance(box, gym.spaces.Box)
        self.mean = np.asarray(mean, dtype=np.float64)
        self.std = np.where(np.asarray(std) < 1e-6, 1.0, np.asarray(std, dtype=np.float64))
        low, high = (box.low - self.mean) / self.std, (box.high - self.mean) / self.std
        self.action_space = gym.spaces.Box(
            low.astype(np.float32), high.astype(np.float32), dtype=np.float32
        )
        self._m, self._s = self.mean.tolist(), self.std.tolist()

    def action(self, action: Any) -> np.ndarray:
        if type(action) is np.ndarray and action.shape == (4,):
            a0, a1, a2, a3 = action.tolist()
            (m0, m1, m2, m3), (s0, s1, s2, s3) = self._m, self._s
            return np.array((a0 * s0 + m0, a1 * s1 + m1, a2 * s2 + m2, a3 * s3 + m3))
        raw: np.ndarray = np.asarray(action, dtype=np.float64) * self.std + self.mean
        return raw

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        return self.env.step(self.action(action))


class Remembering(gym.ObservationWrapper):
    """``env``'s observation extended by a policy's memory (``policies.memory``), as the
    policy extends it in flight (``MLPPolicy.remember``): a fresh memory from ``fresh`` (the
    policy's ``memory_maker``) at each reset, then the observation (as float32) followed by
    the memory once it has taken that observation in, within its bounds (``LoopMemory``)."""

    def __init__(self, env: gym.Env, fresh: Callable[[], Any]) -> None:
        super().__init__(env)
        self.fresh = fresh
        self.memory = fresh()
        box = env.observation_space
        assert isinstance(box, gym.spaces.Box) and len(box.shape) == 1, box
        bound = self.memory.bounds
        low = np.r_[box.low, -bound].astype(np.float32)
        high = np.r_[box.high, bound].astype(np.float32)
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)

    def reset(self, **kwargs: Any) -> tuple[np.ndarray, dict[str, Any]]:
        self.memory = self.fresh()  # as the policy starts each episode: a new memory
        return super().reset(**kwargs)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        obs = np.asarray(observation, dtype=np.float32)
        return np.concatenate([obs, self.memory(obs)])


def make_env(
    spec: dict[str, Any],
    mean: list[float],
    std: list[float],
    success_bonus: float = 0.0,
    memory: Callable[[], Any] | None = None,
) -> gym.Env:
    """One training env (picklable, built in its own process): the flight ``spec`` taking
    actions in the policy's normalised units, its episodes' task returns logged
    (stable-baselines3's ``Monitor``, ``rollout/ep_rew_mean``), its reward with the success
    bonus (``rl.reward.per_env``); with ``memory`` (the policy's ``memory_maker``), its
    observation extended by the memory (``Remembering``, outermost: the reward judges the
    flight's own observation)."""
    from stable_baselines3.common.monitor import Monitor

    flight = FlightSpec.from_dict(spec)
    env = normalized_actions(flight.make_env(), np.array(mean), np.array(std))
    env = reward.per_env(Monitor(env), success_bonus)
    return env if memory is None else Remembering(env, memory)


def training_envs(env_fn: Callable[[], gym.Env], n: int, sampler: str = "grouped") -> Any:
    """``n`` envs built by ``env_fn``, as ``train ppo`` samples them: a single env in this
    process; else, for the ``grouped`` sampler, grouped in one process per core
    (``rl.grouped.GroupedVecEnv``), for ``sb3``, stable-baselines3's ``SubprocVecEnv`` (one
    process per env). Both seed env k with seed + k and step it the same."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    if n == 1:
        return DummyVecEnv([env_fn])
    if sampler == "sb3":
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        return SubprocVecEnv([env_fn] * n, start_method=method)
    from gymfg_il.rl.grouped.vec import GroupedVecEnv

    return GroupedVecEnv([env_fn] * n, len(os.sched_getaffinity(0)))
