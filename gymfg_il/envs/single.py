"""The gymnasium adapter: one aircraft flying one task (registered as ``GymFG/<Family>-v0``)."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.envs.actions import controls
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.options import FlightOptions, options_problem
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import World
from gymfg_il.errors import ConfigError, EnvStateError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ
from gymfg_il.tasks.base import Task
from gymfg_il.tasks.scenery import landmarks_of
from gymfg_il.tasks.targets import TargetTask
from gymfg_il.viz.camera import Camera
from gymfg_il.viz.window import FrameWindow


class AircraftEnv(gym.Env[np.ndarray, np.ndarray]):
    """One JSBSim aircraft flying one task, with the standard gymnasium API.

    Args:
        task: a task name (``altitude``, ``roll``, ``pitch``, ``heading``, ``airspeed``,
            ``sideslip``, ``level``, ``dummy``, or a maneuver: ``turn``, ``climb-turn``,
            ``waypoints``, ``formation``, ``approach``), a task of your own by import path
            (``package.module:ClassName``), a Task class, or a configured Task instance.
        aircraft: JSBSim model (``c172p``, ``f15``, ``A320``, any of
            ``gymfg_il.aircraft.available_models()``).
        options: the other flight options, as keywords (``envs.options.FlightOptions``):
            ``dynamic`` (the family's moving target instead of a static one),
            ``task_kwargs`` (arguments of the task class, e.g. ``{"target_range": (-500,
            500)}``), ``agent_hz`` (an exact divisor of ``sim_hz``), ``sim_hz`` (JSBSim's
            rate), ``episode_time_s`` (reaching it sets ``truncated``; default: the task's
            own, 90 s for most tasks), ``turbulence``, ``wind_kt`` and ``wind_from_deg``
            (the weather, ``sim.weather``: JSBSim's turbulence, none, light, moderate or
            severe, and a steady wind, seeded per episode) and ``trimmed_starts`` (start
            each episode in trimmed straight, level flight, the controls at the trim: the
            default, ``sim.trim``; False: untrimmed with centred surfaces).
        views: UDP ports of FlightGear views of the aircraft (``flightgear.launcher``); with a
            view attached the env runs at real time.
        render_mode: ``None``, ``"rgb_array"`` (``render()`` returns the camera's frame,
            (height, width, 3) uint8) or ``"human"`` (a window shows it at every reset and
            step, paced to real time at ``metadata["render_fps"]`` = ``agent_hz``).
        camera: the view ``render()`` draws (``viz.camera``: ``front``, the pilot's eye, or
            ``chase``), with the task's landmarks (runway, gates, lead).
        render_size: (width, height) of rendered frames.

    Observation: the task's observation (float32, names in ``env.observation_names``; see the
    task's docstring for the table with units). Action: ``Box([-1, -1, -1, 0], [1, 1, 1, 1])`` =
    ``[aileron, elevator, rudder, throttle]``; values outside are clipped, NaN/inf raise
    ``ActionError``. Reward, start state and episode end: the task's docstring. ``terminated``
    when the aircraft crashes, stalls or leaves its envelope (``info["reason"]``);
    ``truncated`` at ``episode_time_s``. The time limit lives in the env, in seconds, because
    a step count depends on ``agent_hz``.

    ``reset(options=...)`` takes ``initial_conditions`` (an ``InitialConditions``) and
    ``target`` (a fixed target for that episode, in the task's convention).

    ``env.flight`` is the ``FlightSpec`` of what this env flies; ``AircraftEnv.from_flight``
    builds the env a spec describes.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": DEFAULT_AGENT_HZ}  # noqa: RUF012

    def __init__(
        self,
        task: str | type[Task] | Task = "altitude",
        aircraft: str = "c172p",
        *,
        views: Sequence[int] | None = None,
        render_mode: str | None = None,
        camera: str = "front",
        render_size: tuple[int, int] = (128, 128),
        **options: Any,
    ) -> None:
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ConfigError(
                f"render_mode={render_mode!r} is not supported; use None, 'rgb_array' or 'human'"
            )
        problem = options_problem(options)
        if problem is not None:
            raise problem
        flight_options = FlightOptions(aircraft=aircraft, **options)
        seen = {"ego": list(views)} if views else None
        flight: FlightSpec | None = None
        if isinstance(task, str):
            flight = dataclasses.replace(flight_options, task=task).flight()
            self.world = World(flight.build_teams(), flight.env_config(views=seen))
        else:
            team = _team_flying(task, aircraft, flight_options)
            self.world = World([team], flight_options.env_config(views=seen))
        self.aircraft = self.world.teams[0].aircraft[0]
        self.flight = flight or FlightSpec.of_world(self.world)
        self._slot = self.world.slots[0]
        self.task = self._slot.task
        low, high = self.task.observation_bounds()
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self.action_space = gym.spaces.Box(ACTION_LOW, ACTION_HIGH, dtype=np.float32)
        self.observation_names = self.task.observation_names
        self.render_mode = render_mode
        self.metadata = {**type(self).metadata, "render_fps": self.world.config.agent_hz}
        self.camera = Camera(*render_size, view=camera)
        self._window: FrameWindow | None = None
        self._cameras: dict[tuple[str, int], Camera] = {}
        self._done = True

    @classmethod
    def from_flight(
        cls, flight: FlightSpec, views: Sequence[int] | None = None, **kwargs: Any
    ) -> AircraftEnv:
        """The env of a solo flight spec (``kwargs``: render_mode, camera, render_size)."""
        return cls(views=views, **FlightOptions.of(flight).given(), **kwargs)

    @property
    def dt(self) -> float:
        return self.world.dt

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        options = dict(options or {})
        ic = options.pop("initial_conditions", None)
        target = options.pop("target", None)
        if options:
            raise ConfigError(
                f"unknown reset options {sorted(options)}; known: initial_conditions, target"
            )
        if ic is not None and not isinstance(ic, InitialConditions):
            raise ConfigError(f"initial_conditions must be InitialConditions, got {ic!r}")
        overrides = {"ego": ic} if ic is not None else None
        task = self.task
        if target is not None:
            if not isinstance(task, TargetTask):
                raise ConfigError(f"{type(task).__name__} has no target to set")
            saved, task.fixed_target = task.fixed_target, float(target)
            try:
                self.world.reset(self.np_random, overrides)
            finally:
                task.fixed_target = saved
        else:
            self.world.reset(self.np_random, overrides)
        self._done = False
        slot = self._slot
        info = {"target": task.target_value(0), "start": slot.state.copy()}
        if self.render_mode == "human":
            self.render()
        return task.observe(slot.state, 0), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._done:
            raise EnvStateError("call reset() before step(), and again after an episode ends")
        ctrl = controls(action)
        world = self.world
        world.advance((ctrl,))
        slot = self._slot
        terminated = slot.terminated
        truncated = world.steps >= world.max_steps and not terminated
        self._done = terminated or truncated
        info = {"reason": slot.reason} if terminated else {}
        if self.render_mode == "human":
            self.render()
        return slot.task.observe(slot.state, world.steps), slot.reward, terminated, truncated, info

    def render(self) -> np.ndarray | None:
        """The camera's frame of the current state (``rgb_array``), or show it (``human``)."""
        if self.render_mode is None:
            gym.logger.warn("render() needs a render_mode (rgb_array or human) at make()")
            return None
        frame = self._draw(self.camera)
        if self.render_mode == "rgb_array":
            return frame
        if self._window is None:
            title = f"GymFG {self.task.name}"
            self._window = FrameWindow(fps=self.metadata["render_fps"], title=title)
        self._window.show(frame)
        return None

    def camera_frame(self, view: str = "front", size: int = 128) -> np.ndarray:
        """A square frame of ``size`` pixels from the ``view`` camera of the current state,
        with the task's landmarks: what a vision policy sees (``render()`` draws the env's
        own ``camera``)."""
        camera = self._cameras.get((view, size))
        if camera is None:
            camera = self._cameras[(view, size)] = Camera(size, size, view=view)
        return self._draw(camera)

    def _draw(self, camera: Camera) -> np.ndarray:
        task = self.task
        marks = landmarks_of(task, getattr(task, "plan", None), self.world.steps)
        return camera.frame(self._slot.state, marks)

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
            self._window = None
        if self.world.slots:
            self.world.close()
            self.world.pool.close()


def _team_flying(task: type[Task] | Task, aircraft: str, options: FlightOptions) -> Team:
    """The one-aircraft team of a task given as a class (built with ``task_kwargs``) or as
    an instance."""
    kwargs = dict(options.task_kwargs or {})
    if isinstance(task, type) and issubclass(task, Task):
        spec: Any = functools.partial(task, **kwargs)
    elif isinstance(task, Task):
        if kwargs:
            raise ConfigError("task_kwargs apply to a task name or class, not an instance")
        spec = task
    else:
        raise ConfigError(f"task={task!r} must be a family name, a Task class or instance")
    cls = task if isinstance(task, type) else type(task)
    ego = Aircraft(aircraft, "ego")
    seconds = options.episode_time_s
    if seconds is None:
        seconds = cls.episode_time_for(ego.profile)
    return Team("ego", [(ego, spec)], episode_time_s=seconds)
