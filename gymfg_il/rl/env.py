"""The env PPO trains in (``rl.run``): the policy's own flight, taking actions in the
policy's normalised units (``NormalizedActions``), judged at the end of each episode as
``eval`` judges it, with a bonus on success (``SuccessBonus``) and, if asked, a cost for
flying near the stall speed (``StallMargin``) or banked steeply (``BankLimit``).

The task's reward is shaped for flying near the target, and most of an episode's return
comes on the way there: a policy that reaches the target and then wanders outside its
tolerance earns nearly the return of one that holds it (the c172p's altitude in moderate
turbulence: the controller 580, a cloned policy 545, success 100 % against 56 %). The bonus
puts the task's own verdict into the return, in the last steps, where the verdict is decided.
The bonus comes at the time limit, so the critic is told the time (``EpisodeClock``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.tasks.verdicts import judge_flight


class NormalizedActions(gym.ActionWrapper):
    """Actions in a policy's normalised units (``(action - mean) / std`` of its dataset):
    the env receives ``action * std + mean``; the space is the contract's box in those
    units, so PPO's clipping keeps every action inside the contract."""

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

    def action(self, action: np.ndarray) -> np.ndarray:
        raw: np.ndarray = np.asarray(action, dtype=np.float64) * self.std + self.mean
        return raw


class SuccessBonus(gym.Wrapper):
    """At the end of each episode, judge it as ``eval`` does (``tasks.verdicts``: a maneuver
    by its judge, a target task by the held error; an episode that terminated failed), set
    ``info["is_success"]`` (stable-baselines3 logs it as ``rollout/success_rate``) and add
    ``share`` x the episode's steps to the last reward of a success (a step's task reward is
    at most about 1)."""

    def __init__(self, env: gym.Env, share: float) -> None:
        super().__init__(env)
        self.share = share
        self._flight: Any = env.unwrapped
        self._states: list[np.ndarray] = []
        self._errors: list[float] = []
        self._task: dict[str, Any] = {}
        self._at: int | None = None

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        self._task = self._flight.task.describe()
        tracked = self._task.get("tracked") or {}
        names = list(self._task.get("observation", []))
        self._at = names.index(tracked["error"]) if tracked.get("error") in names else None
        self._states = [self._state()]
        self._errors = []
        return obs, info

    def _state(self) -> np.ndarray:
        state: np.ndarray = self._flight.world.slots[0].state.copy()
        return state

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._states.append(self._state())
        if self._at is not None:
            self._errors.append(float(obs[self._at]))
        if terminated or truncated:
            # a maneuver the library cannot judge (a task of your own) earns no bonus
            success = False if terminated else self._judge()
            if success is not None:
                info["is_success"] = success
            if success:
                reward = float(reward) + self.share * (len(self._states) - 1)
        return obs, float(reward), terminated, truncated, info

    def _judge(self) -> bool | None:
        flight = self._flight
        gusty = flight.flight.turbulence != "none"
        errors = np.asarray(self._errors)
        success, _, _ = judge_flight(self._task, np.vstack(self._states), errors, flight.dt, gusty)
        return success


def make_env(
    spec: dict[str, Any], mean: list[float], std: list[float], success_bonus: float = 0.0
) -> gym.Env:
    """One training env (picklable, built in its own process): the flight ``spec`` taking
    actions in the policy's normalised units, its episodes' task returns logged
    (stable-baselines3's ``Monitor``, ``rollout/ep_rew_mean``: without the bonus), with
    ``success_bonus`` judged (``SuccessBonus``)."""
    from stable_baselines3.common.monitor import Monitor

    flight = FlightSpec.from_dict(spec)
    env = flight.make_env()
    out: gym.Env = Monitor(NormalizedActions(env, np.array(mean), np.array(std)))
    if success_bonus:
        out = SuccessBonus(out, success_bonus)
    return out
