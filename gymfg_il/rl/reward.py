"""What PPO maximises, composed here and nowhere else. Each step's reward is, in this order:

1. the task's reward (the flight env's own, ``tasks``: shaped for flying near the target, at
   most about 1 a step);
2. plus, at the end of an episode the task judges a success as ``eval`` judges it,
   ``success_bonus`` x the episode's steps (``SuccessBonus``): the task's reward is mostly
   earned on the way to the target, and the bonus puts the verdict, which judges the hold
   at the end, into the return;
3. divided by the running spread of the discounted return, never clipped (``normalize``,
   stable-baselines3's ``VecNormalize``; the bonus comes as one large reward, which a clip
   would cut).

Terms 1 and 2 are computed in each training env (``per_env``, ``rl.envs.make_env``), term 3
over the vector env in the trainer (``normalize``, ``rl.run``). The logged episode return
(``rollout/ep_rew_mean``) is term 1 alone.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.tasks.verdicts import EpisodeVerdict


def per_env(env: gym.Env, success_bonus: float) -> gym.Env:
    """Terms 1 and 2 on one training env (``env``: the flight, its reward the task's)."""
    return SuccessBonus(env, success_bonus) if success_bonus else env


def normalize(venv: Any, gamma: float) -> Any:
    """Term 3 over the vector env ``venv``: rewards scaled by the running spread of the return
    discounted by ``gamma``, never clipped; observations left as they are (the policy
    normalises its own)."""
    from stable_baselines3.common.vec_env import VecNormalize

    return VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=gamma, clip_reward=math.inf)


class SuccessBonus(gym.Wrapper):
    """At the end of each episode, judge it as ``eval`` does (``tasks.verdicts.EpisodeVerdict``:
    a maneuver by its judge, a target task by the held error; an episode that terminated
    failed), set ``info["is_success"]`` (stable-baselines3 logs it as
    ``rollout/success_rate``) and add ``share`` x the episode's steps to the last reward of a
    success (a step's task reward is at most about 1)."""

    def __init__(self, env: gym.Env, share: float) -> None:
        super().__init__(env)
        self.share = share
        self._flight: Any = env.unwrapped
        self._verdict: EpisodeVerdict | None = None

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        flight = self._flight
        # judged by the library's judge of the task the record names (not a task's own)
        record = flight.task.describe()
        self._verdict = EpisodeVerdict(record, flight.dt, flight.flight.gusty)
        self._verdict.start(self._state())
        return obs, info

    def _state(self) -> np.ndarray:
        state: np.ndarray = self._flight.world.slots[0].state
        return state

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        verdict = self._verdict
        assert verdict is not None, "reset() first"
        verdict.add(self._state(), obs)
        if terminated or truncated:
            # a maneuver the library cannot judge (a task of your own) earns no bonus
            found = verdict.judge("terminated" if terminated else None)
            if found is not None:
                info["is_success"] = found.success
            if found is not None and found.success:
                reward = float(reward) + self.share * verdict.steps
        return obs, float(reward), terminated, truncated, info
