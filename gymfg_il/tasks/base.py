"""The Task: what one aircraft observes, how it is rewarded, when it stops, and how it starts.

A task instance belongs to one aircraft in one environment (the environment builds it from the
team roster). Subclasses set ``observation_vars`` and override ``reward`` (or any hook); a new
reward without a subclass is one lambda: ``DummyTask(reward=lambda ctx: ...)``.

A task also owns what the rest of the toolkit knows of it: what the window shows a pilot of
it (``guidance_lines``, ``guidance_values``: ``tasks.guidance``), which target it brings
within which tolerance (``tracked``: the verdict's, ``tasks.verdicts``), and the structure of
its expert (``expert``: ``tasks.experts``), which the controllers and the synthetic pilot
build their loops from.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from gymfg_il.aircraft import Aircraft, FlightProfile
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import BY_NAME, INDEX, indices
from gymfg_il.tasks.experts import Expert
from gymfg_il.tasks.guidance import Line, target_bugs
from gymfg_il.tasks.rewards import RewardContext, RewardFn

# The flight state every built-in task observes, before its own extras.
FLIGHT_VARS: tuple[str, ...] = (
    "altitude_ft",
    "vertical_speed_fps",
    "roll_deg",
    "pitch_deg",
    "airspeed_kts",
    "p_rad_s",
    "q_rad_s",
    "r_rad_s",
    "alpha_deg",
    "beta_deg",
)

_AGL = INDEX["altitude_agl_ft"]
_ALT = INDEX["altitude_ft"]
_VC = INDEX["airspeed_kts"]
_P, _Q, _R, _NZ = (INDEX[n] for n in ("p_rad_s", "q_rad_s", "r_rad_s", "load_factor_g"))


# beyond these JSBSim has diverged, not flown: no aircraft turns at 20 rad/s or pulls 30 g
# (an A320 that struck the ground between two agent steps came back at 3e17 rad/s and 1e35 g,
# then NaN)
MAX_RATE_RAD_S = 20.0
MAX_LOAD_G = 30.0


def diverged(state: np.ndarray) -> bool:
    """Whether ``state`` is not a flight: NaN, or rates and loads no aircraft reaches
    (JSBSim blew up, typically on a ground strike between two agent steps)."""
    # written so that NaN fails every comparison
    return not (
        abs(state[_AGL]) < math.inf
        and abs(state[_VC]) < math.inf
        and abs(state[_NZ]) < MAX_LOAD_G
        and abs(state[_P]) < MAX_RATE_RAD_S
        and abs(state[_Q]) < MAX_RATE_RAD_S
        and abs(state[_R]) < MAX_RATE_RAD_S
    )


class Task:
    """Base task: observe ``observation_vars``, reward 0, stop on leaving the envelope.

    Args:
        reward: a ``Callable[[RewardContext], float]`` that replaces the task's own reward.
        history_window: how many (state, action) pairs before the previous step the reward
            context keeps in ``ctx.history`` (0: only previous and current, the paper's default).
        start: a fixed start state; by default each episode draws one around the aircraft's
            cruise profile (altitude +/- 500 ft, any heading, airspeed +/- 5 %).
    """

    name: ClassVar[str] = "task"
    _call: tuple[tuple[Any, ...], dict[str, Any]] = ((), {})
    observation_vars: ClassVar[tuple[str, ...]] = FLIGHT_VARS
    extra_names: ClassVar[tuple[str, ...]] = ()
    # how long an episode of this task lasts unless the flight says otherwise (seconds)
    episode_time_s: ClassVar[float] = 90.0
    # what the window shows beyond the primary instruments (``guidance_lines``)
    guidance: ClassVar[tuple[Line, ...] | None] = None
    # what a policy cloned from this task's own expert remembers (``memory``); None: what a
    # clone of anyone's demonstrations does
    expert_memory: ClassVar[str | None] = None
    # the DART noise of its autopilot's demonstrations unless a collection sets one (the std
    # added to each executed control; ``collect autopilot --noise``)
    demonstration_noise: ClassVar[float] = 0.1

    @classmethod
    def episode_time_for(cls, profile: FlightProfile) -> float:
        """How long an episode lasts on an aircraft of ``profile`` unless the flight says
        otherwise (seconds): ``episode_time_s`` (maneuvers stretch it for slow turners)."""
        return cls.episode_time_s

    def __new__(cls, *args: Any, **kwargs: Any) -> Task:
        # the arguments of the construction, whatever the subclass takes: what a flight spec
        # records (``options``) to build the same task again
        task = super().__new__(cls)
        task._call = (args, dict(kwargs))
        return task

    @property
    def options(self) -> dict[str, Any]:
        """The arguments this task was built with, by name (a flight spec records them)."""
        args, kwargs = self._call
        if not args:
            return dict(kwargs)
        bound = inspect.signature(type(self)).bind_partial(*args, **kwargs)
        return dict(bound.arguments)

    def __init__(
        self,
        *,
        reward: RewardFn | None = None,
        history_window: int = 0,
        start: InitialConditions | None = None,
    ) -> None:
        if reward is not None and not callable(reward):
            raise ConfigError(f"reward must be callable (a RewardFn), got {reward!r}")
        if (
            isinstance(history_window, bool)
            or not isinstance(history_window, int)
            or (history_window < 0)
        ):
            raise ConfigError(f"history_window must be an integer >= 0, got {history_window!r}")
        self._custom_reward = reward
        self.history_window = history_window
        self.start = start
        self._obs_idx = indices(self.observation_vars)
        self._n_vars = len(self.observation_vars)
        self.aircraft: Aircraft | None = None
        self.dt = 0.1
        self.max_steps = 900
        self._min_agl = 50.0
        self._min_vc = 0.0
        self._ceiling = 1e9

    # -- wiring -------------------------------------------------------------------------
    def bind(self, aircraft: Aircraft, dt: float, max_steps: int) -> None:
        """Attach the task to its aircraft; the environment calls this once."""
        self.aircraft = aircraft
        self.dt = dt
        self.max_steps = max_steps
        profile = aircraft.profile
        self._min_agl = profile.min_agl_ft
        self._min_vc = profile.min_airspeed_kts
        self._ceiling = profile.ceiling_ft

    @property
    def observation_names(self) -> tuple[str, ...]:
        """Names of the observation vector's entries, in order."""
        return self.observation_vars + self.extra_names

    def observation_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) of the observation, float32, from the catalogue's bounds."""
        low = [BY_NAME[n].low for n in self.observation_vars] + list(self._extra_bounds()[0])
        high = [BY_NAME[n].high for n in self.observation_vars] + list(self._extra_bounds()[1])
        return np.array(low, np.float32), np.array(high, np.float32)

    def _extra_bounds(self) -> tuple[list[float], list[float]]:
        return [], []

    # -- episode ------------------------------------------------------------------------
    def initial_conditions(self, rng: np.random.Generator) -> InitialConditions:
        """This episode's start state (drawn from ``rng`` unless ``start`` fixes it)."""
        if self.start is not None:
            return self.start
        profile = self._profile()
        return InitialConditions(
            altitude_ft=profile.cruise_altitude_ft + float(rng.uniform(-500.0, 500.0)),
            heading_deg=float(rng.uniform(0.0, 360.0)),
            airspeed_kts=profile.cruise_kts * float(rng.uniform(0.95, 1.05)),
        )

    def reset(self, state: np.ndarray, rng: np.random.Generator) -> None:
        """Start an episode from ``state`` (draw targets here); the base task has none."""

    def observe(self, state: np.ndarray, step: int) -> np.ndarray:
        """The observation (float32) of catalogue-ordered ``state`` at agent step ``step``."""
        return state[self._obs_idx].astype(np.float32)

    def reward(self, ctx: RewardContext) -> float:
        """The step's reward: the custom reward if one was given, else ``task_reward``."""
        if self._custom_reward is not None:
            return float(self._custom_reward(ctx))
        return self.task_reward(ctx)

    def task_reward(self, ctx: RewardContext) -> float:
        """The task's own reward; 0 for the base task."""
        return 0.0

    def target_value(self, step: int) -> float | None:
        """The target at ``step`` (None for tasks without one)."""
        return None

    def termination(self, state: np.ndarray) -> str | None:
        """Why the aircraft must stop now (crashed, stalled, ...), or None to go on;
        ``diverged`` when the state is not a flight (NaN, or rates and loads no aircraft
        reaches: JSBSim blew up, typically on a ground strike between two agent steps)."""
        if diverged(state):
            return "diverged"
        agl = state[_AGL]
        if agl < self._min_agl:
            return "crashed"
        if state[_VC] < self._min_vc:
            return "stalled"
        if state[_ALT] > self._ceiling:
            return "above_ceiling"
        return None

    def tracked(self) -> dict[str, Any] | None:
        """The one variable the task brings to a target, for the metrics and plots: its name
        (``variable``), the observation entry holding target minus value (``error``), the
        ``tolerance`` within which it counts as reached and whether the target moves
        (``dynamic``); None for tasks without one."""
        return None

    # -- what a pilot is shown (``tasks.guidance``) --------------------------------------
    def guidance_lines(self) -> tuple[Line, ...]:
        """The readings the window shows for this task beyond the primary instruments: the
        class's ``guidance``; without one, a bug for every target of a primary instrument
        the task observes."""
        if self.guidance is not None:
            return self.guidance
        return target_bugs(self.observation_names)

    def guidance_values(self, observed: Mapping[str, float]) -> list[float]:
        """The values of ``guidance_lines()`` from this step's observation (by name); by
        default the observed entries of the same names."""
        return [observed[line.name] for line in self.guidance_lines()]

    def expert(self) -> Expert | None:
        """The structure of the expert that flies this task (``tasks.experts``), which
        ``controllers.autopilot.controller_for`` builds; None: the task has none."""
        return None

    def memory(self, by_expert: bool = False) -> str:
        """What a policy cloned for this task remembers by default (``train bc --memory
        auto``; ``policies.memory``): `vertical` (its expert's climb-rate and pitch loop
        integrals) where the expert's vertical loop follows a target the task observes,
        `none` where it holds the start altitude (the demonstrations then barely move those
        integrals, and a clone's weights on them are guesses: docs/results/memory.md).
        ``by_expert``: for demonstrations this task's own expert flew (``collect
        autopilot``), whose integral terms the memory starts from and is held near; a task
        may remember more then (``expert_memory``)."""
        if by_expert and self.expert_memory is not None:
            return self.expert_memory
        expert = self.expert()
        followed = expert is not None and isinstance(expert.targets.vertical_source, str)
        return "vertical" if followed else "none"

    def describe(self) -> dict[str, Any]:
        """What the task is, for logs and dataset metadata."""
        return {
            "task": self.name,
            "observation": list(self.observation_names),
            "tracked": self.tracked(),
        }

    def _profile(self) -> FlightProfile:
        if self.aircraft is None:
            raise ConfigError(f"{type(self).__name__} is not bound to an aircraft yet")
        return self.aircraft.profile
