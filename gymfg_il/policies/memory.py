"""What a policy may remember as features: the integrals of the errors its task's expert loops
track (``LoopMemory``), run on the observations the policy sees.

A memoryless policy copies what a demonstrator did at each moment but not what the
demonstrator had been accumulating: the controllers hold altitude by integrating the climb-rate
error and the pitch error, a person by trimming. The task declares its expert's loops
(``Task.expert()``, ``tasks.experts``); ``LoopMemory`` runs those loops (an ``Autopilot``
whose action is thrown away) on the policy's own observations and gives their integrals, one
number per loop, updated in O(1) per step and reset at each episode's start. Training computes
them over each recorded episode in order (``over``), flight step by step (``__call__``): the
same code on the same float32 observations, so both see the same numbers. Where the expert
itself demonstrated, its integral terms (``LoopMemory.expert_gains``) are what a policy's
memory starts from and is held near (``learning.memory.by_expert``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError

# the expert's loops whose error integrals each kind of memory holds, in feature order
LOOPS = {
    "none": (),
    "vertical": ("climb", "pitch"),  # what holds an altitude: climb rate, then pitch
    "loops": ("climb", "pitch", "roll", "speed", "slip"),
}


def feature_names(loops: Sequence[str]) -> tuple[str, ...]:
    """The memory's feature names for ``loops``, in their order."""
    return tuple(f"memory.{loop}_error_integral" for loop in loops)


NAMES = feature_names(LOOPS["loops"])


def names_of(kind: str) -> tuple[str, ...]:
    """The feature names of a kind of memory (``LOOPS``)."""
    return feature_names(LOOPS[kind])


def kind_of(observation_names: Sequence[str]) -> str:
    """The kind of memory whose columns end ``observation_names`` ("none": no memory)."""
    held = tuple(n for n in observation_names if n in NAMES)
    for kind in LOOPS:
        if held == names_of(kind):
            return kind
    raise ConfigError(f"memory columns {list(held)} are no kind of memory ({', '.join(LOOPS)})")


@dataclass(frozen=True)
class LoopMemoryRecipe:
    """What makes a fresh ``LoopMemory`` (built once from a flight spec, ``for_flight``):
    the expert's observation names, aircraft model, step and targets."""

    observation_names: tuple[str, ...]
    model: str
    dt: float
    targets: Any
    gains: Any
    throttle: float
    default: str = "none"  # what the task remembers by default (``Task.memory``)
    by_expert: str = "none"  # ... from its own expert's demonstrations

    @classmethod
    def for_flight(
        cls, spec: Mapping[str, Any], observation_names: Sequence[str]
    ) -> LoopMemoryRecipe:
        """The recipe of the expert that flies ``spec`` (a solo ``FlightSpec.to_dict()``),
        checked to read ``observation_names``, the policy's observation."""
        from gymfg_il.controllers.autopilot import controller_for
        from gymfg_il.envs.flight import FlightSpec

        flight = FlightSpec.from_dict(spec)
        env = flight.make_env()
        try:
            names = tuple(env.task.observation_names)
            if names != tuple(observation_names):
                raise ConfigError(
                    f"memory: the flight {flight.task_label} on {flight.aircraft} observes "
                    f"{list(names)}, the policy {list(observation_names)}"
                )
            model, dt = env.aircraft.model, env.dt
            pilot = controller_for(env.task, model, dt, env.aircraft.profile.cruise_throttle)
            defaults = (env.task.memory(), env.task.memory(by_expert=True))
        finally:
            env.close()
        return cls(names, model, dt, pilot.targets, pilot.gains, pilot.throttle_trim, *defaults)

    def new(self, kind: str = "loops") -> LoopMemory:
        from gymfg_il.controllers.autopilot import Autopilot

        pilot = Autopilot(self.observation_names, self.model, self.dt, self.targets, self.gains)
        pilot.set_throttle_trim(self.throttle)
        return LoopMemory(pilot, LOOPS[kind])


class LoopMemory:
    """The expert's loop integrals over one episode's observations (see the module)."""

    def __init__(self, pilot: Any, loops: Sequence[str] = LOOPS["loops"]) -> None:
        self.pilot = pilot
        self.loops = tuple(loops)
        self.pids = tuple(getattr(pilot, f"{loop}_pid") for loop in loops)
        self.names = feature_names(loops)
        self.vertical_only = set(loops) <= {"climb", "pitch"}

    def reset(self) -> None:
        self.pilot.reset()

    @property
    def bounds(self) -> np.ndarray:
        """How far each integral can go either way: its loop's anti-windup clamp (``PID``:
        what the output range can use; 0 for a loop without an integral term)."""
        return np.array(
            [(p.out_max - p.out_min) / abs(p.ki) if p.ki else 0.0 for p in self.pids],
            dtype=np.float32,
        )

    @property
    def scales(self) -> np.ndarray:
        """What each integral is measured in as a policy's input: its loop's range
        (``bounds``; 1 for a loop without an integral term). Not the data's spread: still-air
        demonstrations barely move the integrals of the loops that only hold a start value,
        and an input divided by that spread reached a hundred times it in a gust."""
        bounds = self.bounds
        return np.where(bounds > 0, bounds, 1.0).astype(np.float32)

    def expert_gains(self) -> np.ndarray:
        """How the expert's action (aileron, elevator, rudder, throttle) moves per unit of
        each integral, (4, loops), while no loop is saturated: its integral term, through
        the pitch loop for the climb-rate loop's (whose integral sets a pitch target that the
        pitch loop's gain and its integral, within the step, answer). What a policy's memory
        starts from and is held near where the data says little."""
        gains = np.zeros((4, len(self.pids)), np.float32)
        pitch = self.pilot.pitch_pid
        through_pitch = pitch.kp + pitch.ki * self.pilot.dt
        along = {"climb": (1, -through_pitch), "pitch": (1, -1.0), "roll": (0, 1.0)}
        along |= {"speed": (3, 1.0), "slip": (2, 1.0)}
        for k, (loop, pid) in enumerate(zip(self.loops, self.pids, strict=True)):
            axis, factor = along[loop]
            if loop == "slip" and self.pilot.targets.sideslip_source is None:
                continue  # coordinated flight: the rudder reads the slip alone, no integral
            gains[axis, k] = factor * pid.ki
        return gains

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        """The integrals once ``observation`` (float32, the policy's) is taken in."""
        taken = np.asarray(observation, dtype=np.float32)
        if self.vertical_only:  # the other loops do not feed these: half the work
            self.pilot.follow_vertical(taken)
        else:
            self.pilot.act(taken)
        return np.array([pid.integral for pid in self.pids], dtype=np.float32)

    def over(self, obs: np.ndarray) -> np.ndarray:
        """The integrals at each frame of one episode's observations (N, n_obs), in order,
        from the episode's start."""
        self.reset()
        return np.stack([self(row) for row in obs]) if len(obs) else np.zeros((0, len(self.pids)))
