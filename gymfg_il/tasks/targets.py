"""Target tasks: bring one variable to a target that is fixed (static) or moves (dynamic).

A family (altitude, roll, pitch, heading, airspeed) is a ``TargetFamily`` record; the named task
classes in ``gymfg_il.tasks.library`` are ``TargetTask`` with a family and a static/dynamic
switch, nothing more.

Dynamic targets follow a seeded schedule built at reset: every ``hold_s`` seconds a new waypoint
is drawn from the target range, and the target moves towards it at the family's ``rate``,
starting from the variable's value at the start of the episode.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import BY_NAME, INDEX
from gymfg_il.tasks.base import FLIGHT_VARS, Task
from gymfg_il.tasks.experts import Expert, Targets
from gymfg_il.tasks.guidance import PRIMARY, Line, bug
from gymfg_il.tasks.rewards import RewardContext, action_change
from gymfg_il.units import wrap_180, wrap_360


@dataclass(frozen=True, slots=True)
class TargetFamily:
    """How one variable is targeted.

    Attributes:
        key: short name (``altitude``), used by the CLI and registered env ids.
        variable: the catalogue variable brought to the target.
        relative: targets are offsets from the episode's start value (else absolute values).
        target_range: (low, high) the target is drawn from (offsets when ``relative``).
        reward_scale: error at which the closeness reward has fallen to 1/e.
        tolerance: error within which the target counts as reached.
        rate: how fast a dynamic target moves (variable units per second).
        angular: errors wrap around 360 degrees.
        extra_vars: catalogue variables observed besides the flight state.
        loop: the autopilot loop that flies it (``tasks.experts.Targets``): its axis and,
            where the axis has modes, the mode (``("vertical", "altitude")``: ``vertical=
            "altitude"`` with the target as ``vertical_source``); None: no expert.
    """

    key: str
    variable: str
    relative: bool
    target_range: tuple[float, float]
    reward_scale: float
    tolerance: float
    rate: float
    angular: bool = False
    extra_vars: tuple[str, ...] = ()
    loop: tuple[str, str | None] | None = None


ALTITUDE = TargetFamily(
    "altitude",
    "altitude_ft",
    True,
    (-1000.0, 1000.0),
    200.0,
    50.0,
    10.0,
    loop=("vertical", "altitude"),
)
ROLL = TargetFamily(
    "roll", "roll_deg", False, (-30.0, 30.0), 5.0, 2.0, 5.0, loop=("lateral", "roll")
)
PITCH = TargetFamily(
    "pitch", "pitch_deg", False, (-4.0, 8.0), 2.0, 1.0, 1.0, loop=("vertical", "pitch")
)
HEADING = TargetFamily(
    "heading",
    "heading_deg",
    True,
    (-90.0, 90.0),
    10.0,
    3.0,
    1.0,
    True,
    ("heading_deg",),
    loop=("lateral", "heading"),
)
AIRSPEED = TargetFamily(
    "airspeed", "airspeed_kts", True, (-20.0, 20.0), 5.0, 3.0, 1.0, loop=("speed", None)
)
# the rudder's task: hold a sideslip angle (a slip), wings level
SIDESLIP = TargetFamily(
    "sideslip", "beta_deg", False, (-4.0, 4.0), 1.0, 0.5, 1.0, loop=("sideslip", None)
)
FAMILIES: dict[str, TargetFamily] = {
    f.key: f for f in (ALTITUDE, ROLL, PITCH, HEADING, AIRSPEED, SIDESLIP)
}

SMOOTHNESS_WEIGHT = 0.05
# the error integral observed by target tasks saturates at this many seconds of full error
INTEGRAL_LIMIT_S = 60.0


class TargetTask(Task):
    """Bring ``family.variable`` to a target; see the named subclasses for the spec tables.

    Args:
        target: a fixed target instead of a drawn one (an offset from the start value for
            relative families: altitude, heading, airspeed; an absolute value for roll, pitch).
        target_range: (low, high) to draw targets from, in the same convention.
        hold_s: dynamic targets only: seconds between waypoints (20 by default).
        reward_scale: error at which the reward's closeness term is 1/e.
        tolerance: error within which the target counts as reached (for success metrics).
        **kwargs: ``reward``, ``history_window`` and ``start`` of ``Task``.
    """

    family: ClassVar[TargetFamily]
    dynamic: ClassVar[bool] = False

    def __init__(
        self,
        *,
        target: float | None = None,
        target_range: tuple[float, float] | None = None,
        hold_s: float | None = None,
        reward_scale: float | None = None,
        tolerance: float | None = None,
        **kwargs: object,
    ) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        hold_s = 20.0 if hold_s is None else hold_s
        fam = self.family
        self.target_range = tuple(target_range) if target_range is not None else fam.target_range
        problems = []
        if len(self.target_range) != 2 or not self.target_range[0] <= self.target_range[1]:
            problems.append(f"target_range={target_range!r} must be (low, high) with low <= high")
        if target is not None and not math.isfinite(target):
            problems.append(f"target={target!r} must be a finite number")
        if not hold_s > 0:
            problems.append(f"hold_s={hold_s!r} must be > 0 seconds")
        self.reward_scale = float(reward_scale if reward_scale is not None else fam.reward_scale)
        self.tolerance = float(tolerance if tolerance is not None else fam.tolerance)
        if not self.reward_scale > 0 or not self.tolerance > 0:
            problems.append("reward_scale and tolerance must be > 0")
        if problems:
            raise ConfigError(f"{type(self).__name__}: " + "; ".join(problems))
        self.fixed_target = target
        self.hold_s = float(hold_s)
        self._var = INDEX[fam.variable]
        self._angular = fam.angular
        # the observed variables' indices and three placeholders for the target's entries
        self._obs_idx_extended = np.r_[self._obs_idx, [0, 0, 0]]
        self._targets: np.ndarray = np.zeros(1)
        self._target_list: list[float] = [0.0]  # the same, as Python floats (read each step)
        self.start_value = 0.0
        self._integral = 0.0
        self._integral_step = -1
        self._integral_limit = self._span() * INTEGRAL_LIMIT_S

    @property
    def observation_vars(self) -> tuple[str, ...]:  # type: ignore[override]
        return FLIGHT_VARS + self.family.extra_vars

    @property
    def extra_names(self) -> tuple[str, ...]:  # type: ignore[override]
        v = self.family.variable
        return (f"{v}_target", f"{v}_error", f"{v}_error_integral")

    def _extra_bounds(self) -> tuple[list[float], list[float]]:
        var = BY_NAME[self.family.variable]
        span = self._span()
        return [var.low, -span, -self._integral_limit], [var.high, span, self._integral_limit]

    def _span(self) -> float:
        var = BY_NAME[self.family.variable]
        return 180.0 if self.family.angular else var.high - var.low

    def _draw(self, rng: np.random.Generator) -> float:
        low, high = self.target_range
        return float(rng.uniform(low, high))

    def _absolute(self, value: float) -> float:
        if self.family.relative:
            value = self.start_value + value
        return wrap_360(value) if self.family.angular else value

    def reset(self, state: np.ndarray, rng: np.random.Generator) -> None:
        self._integral, self._integral_step = 0.0, -1
        self.start_value = float(state[self._var])
        first = self.fixed_target if self.fixed_target is not None else self._draw(rng)
        n = self.max_steps + 1
        if not self.dynamic:
            self._targets = np.full(n, self._absolute(first))
            self._target_list = self._targets.tolist()
            return
        # A rate-limited walk from the start value through seeded waypoints (the first one is
        # ``target`` when given), in the family's offset convention.
        offsets = np.empty(n)
        current = 0.0 if self.family.relative else self.start_value
        waypoint = first
        per_step = self.family.rate * self.dt
        hold = max(1, round(self.hold_s / self.dt))
        for i in range(n):
            offsets[i] = current
            if i and i % hold == 0:
                waypoint = self._draw(rng)
            current += max(-per_step, min(per_step, waypoint - current))
        if self.family.relative:
            offsets += self.start_value
        self._targets = wrap_360(offsets) if self.family.angular else offsets
        self._target_list = self._targets.tolist()

    def target_value(self, step: int) -> float:
        targets = self._target_list
        return targets[step] if step < len(targets) else targets[-1]

    def error(self, value: float, step: int) -> float:
        """Target minus value at ``step`` (wrapped to [-180, 180) for angles)."""
        err = self.target_value(step) - value
        if self.family.angular:
            err = wrap_180(err)
        return err

    def observe(self, state: np.ndarray, step: int) -> np.ndarray:
        n = self._n_vars
        obs = state[self._obs_idx_extended].astype(np.float32)  # its last three written below
        target = self.target_value(step)
        err = target - state.item(self._var)  # Python floats: the same doubles, less overhead
        if self._angular:
            err = wrap_180(err)
        if step > self._integral_step:  # once per step, however often it is observed
            missed = step - self._integral_step if self._integral_step >= 0 else 1
            limit = self._integral_limit
            self._integral = max(-limit, min(limit, self._integral + err * self.dt * missed))
            self._integral_step = step
        obs[n] = target
        obs[n + 1] = err
        obs[n + 2] = self._integral
        return obs

    def task_reward(self, ctx: RewardContext) -> float:
        """closeness(error, reward_scale) - 0.05 * mean |change of the three surfaces|."""
        target = ctx.target if ctx.target is not None else self.target_value(ctx.step)
        err = target - ctx.state.values.item(self._var)
        if self._angular:
            err = wrap_180(err)
        smooth = action_change(ctx.prev_action, ctx.action)
        return math.exp(-abs(err) / self.reward_scale) - SMOOTHNESS_WEIGHT * smooth

    def guidance_lines(self) -> tuple[Line, ...]:
        """The target as a bug on its variable's instrument."""
        instrument = PRIMARY[self.family.variable]
        label = "target " + {"slip": "sideslip"}.get(instrument, instrument)
        return (bug(f"{self.family.variable}_target", label),)

    def expert(self) -> Expert | None:
        """The family's loop (``TargetFamily.loop``) to the ``*_target`` entry; the other
        axes hold their start values."""
        if self.family.loop is None:
            return None
        axis, mode = self.family.loop
        loop: dict[str, Any] = {f"{axis}_source": f"{self.family.variable}_target"}
        if mode is not None:
            loop[axis] = mode
        return Expert(Targets(**loop))

    def tracked(self) -> dict[str, Any]:
        v = self.family.variable
        return {
            "variable": v,
            "error": f"{v}_error",
            "tolerance": self.tolerance,
            "dynamic": self.dynamic,
        }

    def describe(self) -> dict[str, Any]:
        fam = self.family
        return {
            **super().describe(),
            "variable": fam.variable,
            "dynamic": self.dynamic,
            "relative": fam.relative,
            "target_range": list(self.target_range),
            "fixed_target": self.fixed_target,
            "tolerance": self.tolerance,
            # how a moving target moves (datasets record it as the episode's target plan)
            **({"rate": fam.rate, "hold_s": self.hold_s} if self.dynamic else {}),
        }
