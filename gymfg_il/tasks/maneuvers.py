"""Maneuvers: tasks that need a pilot rather than one loop to one target.

Each episode draws a *plan* from the seed (a turn, a pair of targets, three gates, a runway)
at reset; ``describe()["plan"]`` records it, and the task's ``judge(plan, states, dt, gusty)``
says from the flown states alone whether the maneuver succeeded and, if not, why. Evaluation
scores success with the task's own rule, so a dataset, a log or an eval row is judged the same
way. In turbulence (``gusty``) a gust carries any aircraft past a calm-air tolerance for a
moment, so there an error a rule bounds at every moment must average within its tolerance
instead, as the target tasks' rule does (``tasks.verdicts``); a gate is passed or missed and
the lead kept clear of in any air.

Every maneuver observes ``FLIGHT_VARS`` and ``heading_deg`` first, then its own entries (see
each task's table). Start: the aircraft's cruise profile (altitude +/- 500 ft, any heading,
airspeed +/- 5 %, wings level). End: as every task (crash, stall, ceiling: ``terminated``;
the episode time, each task's own ``episode_time_for`` its aircraft unless the flight sets
one: ``truncated``). The action is ``[aileron, elevator, rudder, throttle]``.

Every aircraft flies the same maneuvers in its own time and space. The plans were first drawn
for a light aircraft (``aircraft.REFERENCE_PROFILE``, the c172p's: 110 kt, 25 deg of bank);
an aircraft that turns slower at its profile's cruise speed and ``bank_deg`` stretches the
times of a plan by its ``maneuver_scale`` (how many times longer its turns take: 1 for the
c172p, 1.7 for the f15 at 45 deg of bank, 2.1 for the A320 at 30), and one that flies a
maneuver faster stretches the distances flown in a given time by ``speed_scale``. Both are 1
on the c172p, whose plans are those drawn before the scaling existed, bit for bit. Tolerances
stay as a pilot states them (feet, degrees, knots) on every aircraft. The experts fly each
maneuver banked at most ``bank_deg`` (``ManeuverTask.expert``).

This module holds the shared machinery and the turn tasks; ``tasks.courses`` holds the tasks
flown over the ground (waypoints, approach) and ``tasks.formation`` the formation slot.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np

from gymfg_il.aircraft import REFERENCE_PROFILE, FlightProfile
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.base import FLIGHT_VARS, Task
from gymfg_il.tasks.experts import Expert, Targets
from gymfg_il.tasks.grades import Measure, grade
from gymfg_il.tasks.guidance import Line, bug
from gymfg_il.tasks.rewards import RewardContext, action_change, closeness
from gymfg_il.units import FT_PER_DEG, wrap_180, wrap_360

HOLD_S = 10.0  # the last seconds over which a maneuver's end state must hold
SMOOTHNESS_WEIGHT = 0.05
_ALT, _HDG = INDEX["altitude_ft"], INDEX["heading_deg"]


def size(errors: Any, gusty: bool) -> float:
    """How far ``errors`` went, as a rule bounds it: the largest |error|, in turbulence the
    mean (module docstring); inf for none (nothing was held)."""
    magnitude = np.abs(np.asarray(errors, dtype=np.float64))
    if not magnitude.size:
        return math.inf
    return float(magnitude.mean() if gusty else magnitude.max())


def said_size(gusty: bool) -> str:
    """How ``size`` is said: ``on average`` or ``up to``."""
    return "on average" if gusty else "up to"


@dataclass(frozen=True)
class Verdict:
    """A task's judgement of one flown episode: success, and in words what decided it."""

    success: bool
    detail: str
    measures: tuple[Measure, ...] = ()  # the errors the grade reads (``tasks.grades``)

    @property
    def grade(self) -> str:
        return grade(self.success, self.measures)


def local_ft(states: np.ndarray, origin: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """(north, east) in ft of catalogue-ordered ``states`` (rows) from ``origin`` (lat, lon),
    on a flat earth around the origin (errors below 0.1 % over the few miles a task spans)."""
    lat = states[..., INDEX["lat_deg"]]
    lon = states[..., INDEX["lon_deg"]]
    north = (lat - origin[0]) * FT_PER_DEG
    east = wrap_180(lon - origin[1]) * FT_PER_DEG * math.cos(math.radians(origin[0]))
    return north, east


def hold_steps(dt: float) -> int:
    return max(1, round(HOLD_S / dt))


def _signed(rng: np.random.Generator, low: float, high: float) -> float:
    """A magnitude drawn from [low, high) with a random sign."""
    return float(rng.uniform(low, high)) * (1.0 if rng.random() < 0.5 else -1.0)


class ManeuverTask(Task):
    """Shared machinery: a plan drawn at reset, extra observation entries computed once per
    step from the state and the task's memory, and a judge of flown states."""

    observation_vars = (*FLIGHT_VARS, "heading_deg")
    episode_time_s: ClassVar[float] = 90.0
    # (variable, observation entry of target minus value, tolerance): what plots draw
    tracked_entry: ClassVar[tuple[str, str, float]] = ("heading_deg", "heading_deg_error", 3.0)
    # the expert (``expert``): the autopilot's loops fed from the entries the maneuver
    # observes, and the readings of the window they take their targets from instead when a
    # pilot sees only the window (``tasks.experts.Expert.on_display``)
    expert_targets: ClassVar[Targets | None] = None
    expert_on_display: ClassVar[Mapping[str, Any]] = {}

    @classmethod
    def episode_time_for(cls, profile: FlightProfile) -> float:
        """``episode_time_s`` (the c172p's) stretched by the aircraft's maneuver scale, in
        whole seconds: an aircraft that turns at half the rate gets twice the time."""
        return float(math.ceil(cls.episode_time_s * profile.maneuver_scale))

    @classmethod
    def flown_kts(cls, profile: FlightProfile) -> float:
        """The airspeed an aircraft of ``profile`` flies the maneuver at: its cruise."""
        return profile.cruise_kts

    def speed_scale(self) -> float:
        """How many times faster than ``REFERENCE_PROFILE`` its aircraft flies the maneuver,
        at least 1 (1 on the c172p): what the distances flown in the same time grow by, and
        the experts' track and station gains shrink by."""
        profile = self._profile()
        return max(1.0, self.flown_kts(profile) / self.flown_kts(REFERENCE_PROFILE))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.plan: dict[str, Any] = {}
        self._step = -1
        self._extras: np.ndarray = np.zeros(len(self.extra_names))

    # where an ``*_integral`` entry saturates (its observation bound, which a vision
    # policy's recomputed integral follows)
    integral_limit: ClassVar[float] = 6e4

    def _extra_bounds(self) -> tuple[list[float], list[float]]:
        high = [self.integral_limit if n.endswith("_integral") else 1e6 for n in self.extra_names]
        return [-v for v in high], high

    # -- what each maneuver defines --------------------------------------------------------
    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        raise NotImplementedError

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        """The task's observation entries at ``step`` (called once per step, in order, so it
        may keep memory such as the gate reached)."""
        raise NotImplementedError

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        """The reward's task term (at most 1) from this step's entries."""
        raise NotImplementedError

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        """Whether ``states`` (catalogue order, the reset state first) fly the maneuver
        (``gusty``: flown in turbulence, module docstring)."""
        raise NotImplementedError

    # -- the Task hooks ------------------------------------------------------------------
    def reset(self, state: np.ndarray, rng: np.random.Generator) -> None:
        self.plan = self.draw_plan(state, rng)
        self._step = -1
        self._sync(state, 0)  # the memory starts here, whoever asks first

    def _sync(self, state: np.ndarray, step: int) -> np.ndarray:
        if step != self._step:
            self._extras = np.asarray(self.extras(state, step), np.float64)
            self._step = step
        return self._extras

    def observe(self, state: np.ndarray, step: int) -> np.ndarray:
        n = self._n_vars
        extras = self._sync(state, step)
        obs = np.empty(n + len(extras), np.float32)
        obs[:n] = state[self._obs_idx]
        obs[n:] = extras
        return obs

    def task_reward(self, ctx: RewardContext) -> float:
        state = ctx.state.values
        extras = self._sync(state, ctx.step)
        smooth = action_change(ctx.prev_action, ctx.action)
        return self.shaped(extras, state) - SMOOTHNESS_WEIGHT * smooth

    def expert(self) -> Expert | None:
        """``expert_targets``, flown once bound as its aircraft's pilot would: banked at most
        its profile's ``bank_deg`` (the maneuver gains), the track gain divided by the task's
        ``speed_scale`` (a line closed in the same seconds whatever the speed); unchanged on
        the c172p."""
        targets, on_display = self.expert_targets, self.expert_on_display
        if targets is None:
            return None
        if self.aircraft is None:
            return Expert(targets, on_display=on_display)
        scaled = replace(targets, track_gain=targets.track_gain / self.speed_scale())
        return Expert(scaled, self.aircraft.profile.bank_deg, on_display)

    def tracked(self) -> dict[str, Any]:
        variable, error, tolerance = self.tracked_entry
        return {"variable": variable, "error": error, "tolerance": tolerance, "dynamic": True}

    def describe(self) -> dict[str, Any]:
        return {**super().describe(), "plan": dict(self.plan), "maneuver": True}


class TurnTask(ManeuverTask):
    """Turn by 60-180 degrees either way and roll out on the new heading, holding altitude.

    Observation: ``FLIGHT_VARS`` and ``heading_deg``, then:

    | entry | unit | meaning |
    | --- | --- | --- |
    | turn_remaining_deg | deg | the turn still to fly (positive: right), unwrapped |
    | altitude_ft_error | ft | start altitude - altitude |
    | altitude_ft_error_integral | ft·s | that error summed over the steps times dt |

    Plan: the turn (magnitude drawn from [60, 180) deg, either way) and the start altitude.
    Reward: ``0.3 exp(-|remaining| / 30) + 0.3 exp(-|remaining| / 5) + 0.4 exp(-|altitude
    error| / 100)`` minus the usual smoothness term: half the heading's share at the success
    rule's tolerance, so that settling within it pays (at 30 alone 5 deg off kept 85 % of it).
    Success: the altitude stays within 100 ft of the start throughout and the heading is
    within 5 deg of the new one over the last 10 s. Grade: the altitude error
    throughout and the heading error over the last 10 s.
    Start and end: as every maneuver (module docstring); 90 s episodes on the c172p, times
    the aircraft's ``maneuver_scale`` (153 s on the f15, 186 on the A320).
    """

    name = "turn"
    # from its expert's demonstrations, every loop: from five, 100 % on two sets against
    # 75-100 % without memory (docs/results/memory.md)
    expert_memory = "loops"
    demonstration_noise = 0.2  # its hold is the heading's slope (docs/results/defaults.md)

    extra_names = ("turn_remaining_deg", "altitude_ft_error", "altitude_ft_error_integral")
    tracked_entry = ("heading_deg", "turn_remaining_deg", 5.0)
    altitude_tolerance = 100.0
    heading_tolerance = 5.0
    # the altitude and the new heading as bugs, the turn still to fly with its direction
    guidance = (
        bug("altitude_ft_target", "altitude to hold"),
        bug("heading_deg_target", "new heading"),
        Line("turn_remaining_deg", "deg", "panel", "guidance", "turn still to fly"),
    )

    expert_targets = Targets(
        vertical_source="altitude_ft_error",
        lateral="heading",
        lateral_source="turn_remaining_deg",
        relative=frozenset({"vertical", "lateral"}),
    )
    expert_on_display: ClassVar[Mapping[str, Any]] = {
        "vertical_source": "altitude_ft_target",
        "lateral_source": "turn_remaining_deg",
        "relative": frozenset({"lateral"}),
    }

    def guidance_values(self, observed: Mapping[str, float]) -> list[float]:
        plan = self.plan
        heading = wrap_360(plan["start_heading_deg"] + plan["turn_deg"])
        return [plan["altitude_ft"], heading, observed["turn_remaining_deg"]]

    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        return {
            "turn_deg": _signed(rng, 60.0, 180.0),
            "start_heading_deg": float(state[_HDG]),
            "altitude_ft": float(state[_ALT]),
        }

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        heading = float(state[_HDG])
        if step == 0:
            self._turned, self._last, self._integral = 0.0, heading, 0.0
        self._turned += wrap_180(heading - self._last)
        self._last = heading
        alt_err = self.plan["altitude_ft"] - float(state[_ALT])
        if step:
            limit = self.integral_limit
            self._integral = max(-limit, min(limit, self._integral + alt_err * self.dt))
        return [self.plan["turn_deg"] - self._turned, alt_err, self._integral]

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        loose, tight = closeness(extras[0], 30.0), closeness(extras[0], self.heading_tolerance)
        heading = 0.3 * loose + 0.3 * tight  # tight: at the success rule's tolerance
        return heading + 0.4 * closeness(extras[1], 100.0)

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        turned = np.unwrap(states[:, _HDG], period=360.0)
        turned = turned - turned[0]
        alt_err = np.abs(states[:, _ALT] - plan["altitude_ft"])
        worst = int(alt_err.argmax())
        if size(alt_err, gusty) > cls.altitude_tolerance:
            when = "on average" if gusty else f"at {worst * dt:.1f} s"
            return Verdict(False, f"altitude off by {size(alt_err, gusty):.0f} ft {when}")
        tail = np.abs(plan["turn_deg"] - turned[-hold_steps(dt) :])
        if len(states) <= hold_steps(dt) or size(tail, gusty) > cls.heading_tolerance:
            return Verdict(
                False,
                f"heading off the new one by {said_size(gusty)} {size(tail, gusty):.1f} deg "
                "at the end",
            )
        measures = (
            Measure.of("altitude", "ft", alt_err, cls.altitude_tolerance, mean=gusty),
            Measure.of("heading", "deg", tail, cls.heading_tolerance, mean=gusty),
        )
        return Verdict(True, f"turned {turned[-1]:+.0f} of {plan['turn_deg']:+.0f} deg", measures)


class ClimbTurnTask(ManeuverTask):
    """Reach a new altitude and a new heading together.

    Observation: ``FLIGHT_VARS`` and ``heading_deg``, then:

    | entry | unit | meaning |
    | --- | --- | --- |
    | altitude_ft_target | ft | the new altitude |
    | altitude_ft_error | ft | target - altitude |
    | altitude_ft_error_integral | ft·s | that error summed over the steps times dt |
    | heading_deg_target | deg | the new heading |
    | heading_deg_error | deg | target - heading, wrapped to [-180, 180) |

    Plan: an altitude change of 300-1,000 ft and a heading change of 30-90 deg, each either
    way. Reward: ``0.5 exp(-|altitude error| / 200) + 0.5 exp(-|heading error| / 10)`` minus
    the smoothness term. Success: within 50 ft and 3 deg of both over the last 10 s.
    Grade: the altitude and heading errors over the last 10 s.
    Start and end: as every maneuver (module docstring); 90 s episodes on the c172p, times
    the aircraft's ``maneuver_scale`` (153 s on the f15, 186 on the A320).
    """

    name = "climb-turn"
    # from its expert's demonstrations, every loop: from five, 94 and 100 % on two sets
    # (vertical: 44 and 75 %); from 50, 16 of 16 on the c172p, f15 and A320 (vertical: 16,
    # 13 and 16; docs/results/memory.md)
    expert_memory = "loops"
    extra_names = (
        "altitude_ft_target",
        "altitude_ft_error",
        "altitude_ft_error_integral",
        "heading_deg_target",
        "heading_deg_error",
    )
    tracked_entry = ("altitude_ft", "altitude_ft_error", 50.0)
    altitude_tolerance = 50.0
    heading_tolerance = 3.0
    # the new altitude and heading as bugs (the entries of the same names, which the expert
    # flies to: the window draws its sources already)
    guidance = (bug("altitude_ft_target", "new altitude"), bug("heading_deg_target", "new heading"))
    expert_targets = Targets(
        vertical_source="altitude_ft_target", lateral="heading", lateral_source="heading_deg_target"
    )

    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        return {
            "altitude_ft": float(state[_ALT]) + _signed(rng, 300.0, 1000.0),
            "heading_deg": wrap_360(float(state[_HDG]) + _signed(rng, 30.0, 90.0)),
        }

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        alt_err = self.plan["altitude_ft"] - float(state[_ALT])
        if step == 0:
            self._integral = 0.0
        else:
            limit = self.integral_limit
            self._integral = max(-limit, min(limit, self._integral + alt_err * self.dt))
        hdg = self.plan["heading_deg"]
        return [self.plan["altitude_ft"], alt_err, self._integral, hdg, wrap_180(hdg - state[_HDG])]

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        return 0.5 * closeness(extras[1], 200.0) + 0.5 * closeness(extras[4], 10.0)

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        tail = states[-hold_steps(dt) :]
        alt_err = plan["altitude_ft"] - tail[:, _ALT]
        hdg_err = wrap_180(plan["heading_deg"] - tail[:, _HDG])
        alt, hdg = size(alt_err, gusty), size(hdg_err, gusty)
        ok = len(states) > hold_steps(dt) and alt <= cls.altitude_tolerance
        ok = ok and hdg <= cls.heading_tolerance
        measures = (
            Measure.of("altitude", "ft", alt_err, cls.altitude_tolerance, mean=gusty),
            Measure.of("heading", "deg", hdg_err, cls.heading_tolerance, mean=gusty),
        )
        return Verdict(
            bool(ok),
            f"over the last {HOLD_S:g} s: {said_size(gusty)} {alt:.0f} ft, {hdg:.1f} deg off",
            measures,
        )
