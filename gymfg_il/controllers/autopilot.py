"""Physics-based controllers: PID loops, one per control surface, composed into autopilots.

Loops (each a ``PID`` with explicit ``dt``):

| surface | inner loop | outer loops |
| --- | --- | --- |
| elevator | pitch (damped by pitch rate) | climb rate -> pitch, altitude -> climb rate |
| aileron | roll (damped by roll rate) | heading -> roll |
| throttle | airspeed | |
| rudder | sideslip -> 0 (coordinated flight), or to a target (a slip) | |

``Autopilot`` holds one target per axis (vertical: altitude, climb rate or pitch; lateral: roll
or heading; speed: airspeed), where ``Targets`` (``tasks.experts``) says. Axes left without a
target hold what they had at the first observation of the episode (altitude, wings level,
airspeed), so every task's controller flies a complete aircraft. ``controller_for(task)``
builds the one a task declares (``Task.expert()``).
"""

from __future__ import annotations

import numpy as np

from gymfg_il.controllers.gains import Gains, gains_for, maneuver_gains
from gymfg_il.controllers.pid import PID
from gymfg_il.errors import ConfigError
from gymfg_il.moved import forward_names
from gymfg_il.tasks.experts import Targets
from gymfg_il.tasks.orientation import bank_for_turn_rate
from gymfg_il.units import RAD_TO_DEG, wrap_180

# a heading target turning faster than this jumped (a new target): no turn feed-forward
MAX_FEED_FORWARD_TURN_DEG_S = 10.0
HOLD_START = Targets()  # every axis holds what it had at the episode's first observation


class Autopilot:
    """Fly any aircraft by PID loops from a task observation with named entries.

    Args:
        observation_names: names of the observation's entries (``task.observation_names``).
        model: JSBSim model, selects the gain set.
        dt: seconds per agent step.
        targets: which target each axis follows (``Targets``).
        gains: override the model's gain set.
    """

    def __init__(
        self,
        observation_names: tuple[str, ...],
        model: str,
        dt: float,
        targets: Targets = HOLD_START,
        gains: Gains | None = None,
    ) -> None:
        if not dt > 0:
            raise ConfigError(f"dt must be > 0 seconds, got {dt!r}")
        self.names = tuple(observation_names)
        self.index = {n: i for i, n in enumerate(self.names)}
        need = [
            "altitude_ft",
            "vertical_speed_fps",
            "roll_deg",
            "pitch_deg",
            "airspeed_kts",
            "p_rad_s",
            "q_rad_s",
            "beta_deg",
        ]
        if targets.lateral in ("heading", "track"):
            need.append("heading_deg")
        if targets.lateral == "track":
            need.append(str(targets.track_source))
        if targets.station_source is not None:
            need += [targets.station_source, str(targets.station_rate_source)]
        for source in (targets.vertical_source, targets.lateral_source, targets.speed_source):
            if isinstance(source, str):
                need.append(source)
        self.needs = tuple(dict.fromkeys(need))  # the entries it reads, in order
        missing = [n for n in need if n not in self.index]
        if missing:
            raise ConfigError(f"the observation lacks {missing} that the autopilot reads")
        self.model, self.dt, self.targets = model, dt, targets
        g = self.gains = gains or gains_for(model)
        self.pitch_pid = PID(*g.pitch)
        self.roll_pid = PID(*g.roll)
        self.climb_pid = PID(*g.climb, out_min=-g.max_pitch_deg, out_max=g.max_pitch_deg)
        self.speed_pid = PID(*g.speed, out_min=0.0, out_max=1.0)
        self.slip_pid = PID(*g.slip)
        self.start: list[float] | None = None
        self._last_heading_target: float | None = None
        self._last_altitude_target: float | None = None
        self.throttle_trim = 0.7
        self.rudder_trim = 0.0
        self._observed = self._integrals_in_observation()
        self._from_observation: dict[str, int] = {}

    @property
    def observed_integrals(self) -> dict[str, int]:
        """Loop -> index of the observation entry that sums the same error (the roll task's
        ``roll_deg_error_integral``, the approach's ``airspeed_kts_error_integral``, ...):
        the task's own sum, which keeps summing where the loop's anti-windup stops."""
        return dict(self._observed)

    def reset(self, seed: int | None = None) -> None:
        for pid in (self.pitch_pid, self.roll_pid, self.climb_pid, self.speed_pid, self.slip_pid):
            pid.reset()
        self._from_observation = {}
        self.start = None
        # centred surfaces until start_from says what the aircraft starts with
        self.roll_pid.bias = self.pitch_pid.bias = self.slip_pid.bias = self.rudder_trim = 0.0
        self._last_heading_target = None
        self._last_altitude_target = None

    def track(self, applied: np.ndarray, *, from_observation: bool = False) -> None:
        """Follow an action someone else applied (see ``PID.track``): the surface loops'
        integrals are set so this controller would have output it (a bumpless hand-back
        after a human's takeover).

        ``from_observation`` (labelling under DAgger): a loop whose error integral the
        observation carries (``roll_deg_error_integral`` for a roll target, ...) takes its
        integral from the observation at each later ``act`` instead, so the label is a
        function of the observation alone, which is what a memoryless policy can learn.
        Back-calculating it from the policy's own action would make the label depend on
        that action, which the policy never sees. Not the airspeed's: the task's sum goes on
        while the throttle sits at a limit (idle on a descent, routinely), where the loop's
        stops, and loaded into the loop a wound-up sum held the labels' throttle at idle
        through whole approaches; the speed loop follows what is flown instead."""
        observed = (
            {loop: at for loop, at in self._observed.items() if loop != "speed"}
            if from_observation
            else {}
        )
        self._from_observation = observed
        if "roll" not in observed:
            self.roll_pid.track(float(applied[0]))
        if "pitch" not in observed:
            self.pitch_pid.track(-float(applied[1]))
        if "speed" not in observed:
            self.speed_pid.track(float(applied[3]))
        if "slip" not in observed:  # a no-op in coordinated flight: the loop never ran
            self.slip_pid.track(float(applied[2]))

    def _integrals_in_observation(self) -> dict[str, int]:
        """Loop -> index of the observation entry holding its error integral."""
        t, index = self.targets, self.index
        out = {}
        if t.lateral == "roll" and "roll_deg_error_integral" in index:
            out["roll"] = index["roll_deg_error_integral"]
        if t.vertical == "pitch" and "pitch_deg_error_integral" in index:
            out["pitch"] = index["pitch_deg_error_integral"]
        if isinstance(t.speed_source, str) and "airspeed_kts_error_integral" in index:
            out["speed"] = index["airspeed_kts_error_integral"]
        if t.sideslip_source is not None and "beta_deg_error_integral" in index:
            out["slip"] = index["beta_deg_error_integral"]
        return out

    def _load_integral(self, loop: str, pid: PID, obs: list[float], error: float) -> None:
        """Set ``pid``'s integral so its next update ends at the observed one."""
        at = self._from_observation.get(loop)
        if at is not None:
            limit = (pid.out_max - pid.out_min) / abs(pid.ki)
            pid.integral = max(-limit, min(limit, obs[at] - error * self.dt))

    def set_throttle_trim(self, throttle: float) -> None:
        self.throttle_trim = throttle

    def start_from(self, action: np.ndarray) -> None:
        """Start this episode from the aircraft's start controls (a trimmed start's trim):
        each surface loop and the throttle loop output them while their errors are zero."""
        self.roll_pid.bias = float(action[0])
        self.pitch_pid.bias = -float(action[1])  # positive elevator = nose down
        self.slip_pid.bias = self.rudder_trim = float(action[2])
        self.throttle_trim = float(action[3])

    def _value(
        self, obs: list[float], source: str | float | None, hold: str, axis: str = ""
    ) -> float:
        if source is None:
            assert self.start is not None
            return self.start[self.index[hold]]
        if isinstance(source, str):
            value = obs[self.index[source]]
            return value + obs[self.index[hold]] if axis in self.targets.relative else value
        return float(source)

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        obs = self._taken(observation)
        nose_up = self._vertical(obs)
        aileron = self._lateral(obs)
        throttle = self._speed(obs)
        return np.array([aileron, -nose_up, self._rudder(obs), throttle])

    def follow_vertical(self, observation: np.ndarray) -> None:
        """Run the vertical loops alone on ``observation``, as ``act`` runs them (their
        integrals are a policy's memory, ``policies.memory``; the other loops do not feed
        them)."""
        self._vertical(self._taken(observation))

    def _taken(self, observation: np.ndarray) -> list[float]:
        """The observation as Python floats (the same double arithmetic as numpy scalars, at
        a fraction of the cost); the first of an episode is its start."""
        obs: list[float] = np.asarray(observation, dtype=np.float64).tolist()
        if self.start is None:
            self.start = list(obs)
            self.speed_pid.bias = self.throttle_trim
        return obs

    def _vertical(self, obs: list[float]) -> float:
        """Altitude -> climb rate -> pitch -> elevator, as the nose-up command (positive
        elevator = nose down)."""
        i, g, t, dt = self.index, self.gains, self.targets, self.dt
        if t.vertical == "pitch":
            pitch_target = self._value(obs, t.vertical_source, "pitch_deg")
        else:
            if t.vertical == "climb":
                climb_target = self._value(obs, t.vertical_source, "vertical_speed_fps")
            else:
                alt_target = self._value(obs, t.vertical_source, "altitude_ft", "vertical")
                alt_error = alt_target - obs[i["altitude_ft"]]
                # feed-forward: climb at the target's own rate while it moves (a target that
                # jumps faster than the aircraft can climb is a new target, not a moving one)
                last, self._last_altitude_target = self._last_altitude_target, alt_target
                target_rate = 0.0 if last is None else (alt_target - last) / dt
                if abs(target_rate) > g.max_climb_fps:
                    target_rate = 0.0
                climb_target = g.altitude_to_climb * alt_error + target_rate
            climb_target = max(-g.max_descent_fps, min(g.max_climb_fps, climb_target))
            pitch_target = self.climb_pid(climb_target, obs[i["vertical_speed_fps"]], dt)
        pitch_target = max(-g.max_pitch_deg, min(g.max_pitch_deg, pitch_target))
        self._load_integral("pitch", self.pitch_pid, obs, pitch_target - obs[i["pitch_deg"]])
        return float(
            self.pitch_pid(pitch_target, obs[i["pitch_deg"]], dt, obs[i["q_rad_s"]] * RAD_TO_DEG)
        )

    def _lateral(self, obs: list[float]) -> float:
        """Heading (or a track) -> roll -> aileron."""
        i, g, t, dt = self.index, self.gains, self.targets, self.dt
        if t.lateral in ("heading", "track"):
            heading_target = self._value(obs, t.lateral_source, "heading_deg", "lateral")
            if t.lateral == "track":  # the line's course, turned towards the line
                off = t.track_gain * obs[i[str(t.track_source)]]
                heading_target -= max(-t.track_limit_deg, min(t.track_limit_deg, off))
            err = wrap_180(heading_target - obs[i["heading_deg"]])
            # feed-forward: the bank of a coordinated turn at the target's own turn rate (a
            # jump, such as the next gate's bearing, is a new target, not a turn)
            last, self._last_heading_target = self._last_heading_target, heading_target
            turn = 0.0 if last is None else wrap_180(heading_target - last) / dt
            if abs(turn) > MAX_FEED_FORWARD_TURN_DEG_S:
                turn = 0.0
            roll_target = g.heading_to_roll * err + bank_for_turn_rate(turn, obs[i["airspeed_kts"]])
        else:
            roll_target = self._value(obs, t.lateral_source, "roll_deg")
        roll_target = (
            max(-g.max_roll_deg, min(g.max_roll_deg, roll_target))
            if t.lateral != "roll"
            else roll_target
        )
        self._load_integral("roll", self.roll_pid, obs, roll_target - obs[i["roll_deg"]])
        return float(
            self.roll_pid(roll_target, obs[i["roll_deg"]], dt, obs[i["p_rad_s"]] * RAD_TO_DEG)
        )

    def _speed(self, obs: list[float]) -> float:
        """Airspeed (or station on a slot) -> throttle."""
        i, t = self.index, self.targets
        if t.station_source is not None:
            kp, kd = t.station_gains
            ask = kp * obs[i[t.station_source]] + kd * obs[i[str(t.station_rate_source)]]
            speed_target = obs[i["airspeed_kts"]] + max(-20.0, min(20.0, ask))
        else:
            speed_target = self._value(obs, t.speed_source, "airspeed_kts", "speed")
        self._load_integral("speed", self.speed_pid, obs, speed_target - obs[i["airspeed_kts"]])
        return float(self.speed_pid(speed_target, obs[i["airspeed_kts"]], self.dt))

    def _rudder(self, obs: list[float]) -> float:
        """Sideslip to zero (coordinated flight), or to the task's slip target."""
        i, t = self.index, self.targets
        if t.sideslip_source is None:
            return max(-1.0, min(1.0, self.rudder_trim - self.gains.sideslip * obs[i["beta_deg"]]))
        slip_target = self._value(obs, t.sideslip_source, "beta_deg")  # more rudder, more slip
        self._load_integral("slip", self.slip_pid, obs, slip_target - obs[i["beta_deg"]])
        return float(self.slip_pid(slip_target, obs[i["beta_deg"]], self.dt))


def controller_for(task: object, model: str, dt: float, throttle_trim: float = 0.7) -> Autopilot:
    """The autopilot that flies ``task`` (a bound Task) as the task declares its expert
    (``Task.expert()``, ``tasks.experts``): which target each loop follows, the other axes
    held at their start values, and the gain set (the aircraft's own, or the maneuver gains
    banked at most the expert's ``bank_deg``)."""
    declared = getattr(task, "expert", None)
    expert = declared() if callable(declared) else None
    if expert is None:
        raise ConfigError(
            f"no controller for {type(task).__name__}: declare its expert (Task.expert(), "
            "gymfg_il.tasks.experts) or build an Autopilot yourself"
        )
    gains = None if expert.bank_deg is None else maneuver_gains(model, expert.bank_deg)
    names = task.observation_names  # type: ignore[attr-defined]
    pilot = Autopilot(names, model, dt, expert.targets, gains)
    pilot.set_throttle_trim(throttle_trim)
    return pilot


# names whose knowledge each task now declares itself
__getattr__ = forward_names(
    __name__,
    {},
    gone={
        "MANEUVER_TARGETS": "each maneuver declares its expert's loops (TurnTask.expert_targets, "
        "...; any task: Task.expert(), gymfg_il.tasks.experts)",
        "scaled_for": "ManeuverTask.expert() scales a maneuver's expert for its aircraft",
    },
)
