"""``GroupedPPO``: the fine-tuning PPO (``rl.algorithm.FineTunePPO``) whose rollouts are
sampled in the env processes of a ``GroupedVecEnv``, and filled into stable-baselines3's
buffer as its own ``collect_rollouts`` fills it.

It calls stable-baselines3's private members (``_last_obs``, ``_last_episode_starts``,
``_update_info_buffer``, ``VecNormalize._update_reward``), read in 2.9: the project pins that
minor version, and ``tests/rl/grouped/test_rollouts.py`` holds the buffer it fills to the one
stable-baselines3's own loop fills on the same seeds.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import torch

from gymfg_il.rl.algorithm import FineTunePPO
from gymfg_il.rl.grouped.vec import GroupedVecEnv


class GroupedPPO(FineTunePPO):
    """``FineTunePPO`` sampling its rollouts in the env processes when its envs are grouped
    (``GroupedVecEnv.rollout``); on other envs, stable-baselines3's own loop."""

    def collect_rollouts(
        self, env: Any, callback: Any, rollout_buffer: Any, n_rollout_steps: int
    ) -> bool:
        """stable-baselines3's rollout, sampled in the env processes: the same steps, rewards
        normalised, values bootstrapped, callbacks called and episodes logged step by step as
        its own ``collect_rollouts`` does, from the arrays the processes return."""
        from stable_baselines3.common.vec_env import VecNormalize

        norm = env if isinstance(env, VecNormalize) else None
        grouped = norm.venv if norm is not None else env
        if not isinstance(grouped, GroupedVecEnv) or not isinstance(
            self.action_space, gym.spaces.Box
        ):
            return bool(super().collect_rollouts(env, callback, rollout_buffer, n_rollout_steps))
        assert self._last_episode_starts is not None
        self.policy.set_training_mode(False)
        rollout_buffer.reset()
        callback.on_rollout_start()
        got = grouped.rollout(self.policy, n_rollout_steps, self.seed or 0, self.sde_sample_freq)
        ends: dict[int, list[tuple[int, dict[str, Any]]]] = {}
        for t, i, info in got["ends"]:
            ends.setdefault(t, []).append((i, info))
        for t in range(n_rollout_steps):
            rewards, dones = got["rewards"][t], got["dones"][t]
            if norm is not None:  # as VecNormalize.step_wait does
                if norm.training:
                    norm._update_reward(rewards)
                rewards = norm.normalize_reward(rewards)
                norm.returns[dones] = 0
            rewards = rewards + self.gamma * got["bootstrap"][t]
            infos: list[dict[str, Any]] = [{} for _ in range(env.num_envs)]
            for i, info in ends.get(t, []):
                infos[i] = info
            self.num_timesteps += env.num_envs
            callback.update_locals({"infos": infos, "dones": dones, "rewards": rewards})
            if not callback.on_step():
                return False
            self._update_info_buffer(infos, dones)
            rollout_buffer.add(
                got["obs"][t],
                got["actions"][t],
                rewards,
                self._last_episode_starts,
                torch.as_tensor(got["values"][t]),
                torch.as_tensor(got["log_probs"][t]),
            )
            self._last_episode_starts = dones
        self._last_obs = got["last_obs"]
        rollout_buffer.compute_returns_and_advantage(
            last_values=torch.as_tensor(got["last_values"]), dones=dones
        )
        callback.update_locals({"infos": infos, "dones": dones, "rewards": rewards})
        callback.on_rollout_end()
        return True
