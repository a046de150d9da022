"""A GymFG flight as LeRobot's evaluation loop expects an env to be.

``LeRobotFlightEnv`` wraps the gymnasium ``AircraftEnv`` of one solo flight:

- observation: a dict. ``agent_pos`` is the task's whole observation (``observation.state``
  in our datasets); ``environment_state`` its task columns (``observation.environment_state``);
  ``pixels`` ``{view: (H, W, 3) uint8}``, only with ``images``.
- action: ``[aileron, elevator, rudder, throttle]``, as in every GymFG env; reward and
  episode end are the task's.
- ``info["is_success"]``: on reset and every step; at the episode's end, whether ``eval``
  would count the episode a success (``evaluation.metrics``).
- ``task`` and ``task_description``: the task in words, the string our datasets hold.
- ``render()``: the chase camera; ``metadata["render_fps"]`` is the agent rate.
- ``_max_episode_steps``: the episode's agent steps.

``reset`` accepts LeRobot's ``options={"lerobot_new_rollout": True}``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.datasets.videos import check_views
from gymfg_il.envs.options import FlightOptions, options_problem
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.evaluation.metrics import score_episode
from gymfg_il.evaluation.trace import make_trace
from gymfg_il.recording.session import task_description
from gymfg_il.sim.properties import task_columns
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, episode_steps

NEW_ROLLOUT = "lerobot_new_rollout"


class LeRobotFlightEnv(gym.Env):
    """One aircraft flying ``task`` (see the module docstring for what LeRobot sees).

    Args:
        task: our task name (roll, altitude, turn, approach, ...).
        images: camera views given as ``pixels`` (``front``, ``chase``).
        image_size: their square size in pixels.
        options: the other flight options (``envs.options.FlightOptions``: ``aircraft``,
            ``dynamic``, ``episode_time_s``, ``agent_hz``, the dataset's fps,
            ``turbulence``, ...).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": DEFAULT_AGENT_HZ}  # noqa: RUF012

    def __init__(
        self,
        task: str = "roll",
        *,
        images: Sequence[str] = (),
        image_size: int = 128,
        render_mode: str = "rgb_array",
        **options: Any,
    ) -> None:
        problem = options_problem(options)
        if problem is not None:
            raise problem
        flight = FlightOptions(task=task, **options).flight()
        self.flight = flight
        self.env = AircraftEnv.from_flight(flight, render_mode="rgb_array", camera="chase")
        self.render_mode = render_mode
        self.metadata = {**type(self).metadata, "render_fps": flight.agent_hz}
        names = self.env.observation_names
        self._environment = task_columns(names)
        self.images = tuple(check_views(list(images)))
        self.image_size = int(image_size)
        box = self.env.observation_space
        assert isinstance(box, gym.spaces.Box)
        low, high = box.low, box.high
        spaces: dict[str, gym.Space] = {"agent_pos": gym.spaces.Box(low, high, dtype=np.float32)}
        if self._environment:
            idx = self._environment
            spaces["environment_state"] = gym.spaces.Box(low[idx], high[idx], dtype=np.float32)
        if self.images:
            shape = (self.image_size, self.image_size, 3)
            spaces["pixels"] = gym.spaces.Dict(
                {v: gym.spaces.Box(0, 255, shape, dtype=np.uint8) for v in self.images}
            )
        self.observation_space = gym.spaces.Dict(spaces)
        self.action_space = self.env.action_space
        self._max_episode_steps = episode_steps(flight.episode_time_s, flight.agent_hz)
        self.task = task_description(self.env.task, flight.aircraft)
        self.task_description = self.task
        self._seed = -1
        self._steps: dict[str, list[Any]] = {}

    def _observation(self, obs: np.ndarray) -> dict[str, Any]:
        out: dict[str, Any] = {"agent_pos": obs}
        if self._environment:
            out["environment_state"] = obs[self._environment]
        if self.images:
            size = self.image_size
            out["pixels"] = {v: self.env.camera_frame(v, size) for v in self.images}
        return out

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        options = dict(options or {})
        options.pop(NEW_ROLLOUT, None)
        obs, info = self.env.reset(seed=seed, options=options or None)
        self._seed = -1 if seed is None else int(seed)
        state = self.env.world.slots[0].state.copy()
        self._steps = {"obs": [], "action": [], "reward": [], "state": [state]}
        return self._observation(obs), {**info, "is_success": False}

    def step(self, action: np.ndarray) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        steps = self._steps
        steps["obs"].append(obs)
        steps["action"].append(np.asarray(action, dtype=np.float64).reshape(4))
        steps["reward"].append(reward)
        steps["state"].append(self.env.world.slots[0].state.copy())
        success = False
        if terminated or truncated:
            success = self._judge(terminated, info.get("reason"))
        info = {**info, "is_success": success}
        return self._observation(obs), reward, terminated, truncated, info

    def _judge(self, terminated: bool, reason: str | None) -> bool:
        """Whether ``eval`` would count the episode flown so far a success."""
        steps = self._steps
        trace = make_trace(
            self.env.task.describe(),
            self._seed,
            self.env.dt,
            np.array(steps["obs"]),
            np.array(steps["action"]),
            np.array(steps["reward"], dtype=np.float64),
            terminated,
            reason,
            np.array(steps["state"]),
            gusty=self.flight.gusty,
        )
        return score_episode(trace).success

    def render(self) -> np.ndarray:
        frame = self.env.render()
        assert frame is not None  # rgb_array
        return frame

    def close(self) -> None:
        self.env.close()
