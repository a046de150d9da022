"""A PID controller with explicit time step, output limits, anti-windup and derivative on
measurement (no derivative kick when the setpoint jumps)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from gymfg_il.errors import ConfigError


@dataclass
class PID:
    """``u = kp*e + ki*∫e dt - kd*d(measurement)/dt``, clamped to ``[out_min, out_max]``.

    Anti-windup: the integral stops growing while the output is saturated in the direction
    the error pushes, and is clamped to what the output range can use.

    Args:
        kp, ki, kd: gains.
        out_min, out_max: output limits.
        bias: added to the output (a trim value, e.g. cruise throttle).
    """

    kp: float
    ki: float = 0.0
    kd: float = 0.0
    out_min: float = -1.0
    out_max: float = 1.0
    bias: float = 0.0
    integral: float = field(default=0.0, init=False)
    _last: float | None = field(default=None, init=False, repr=False)
    _inputs: tuple[float, float] | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        values = (self.kp, self.ki, self.kd, self.out_min, self.out_max, self.bias)
        if not all(math.isfinite(v) for v in values):
            raise ConfigError(f"PID gains and limits must be finite, got {self!r}")
        if self.out_min >= self.out_max:
            raise ConfigError(f"PID needs out_min < out_max, got {self.out_min}, {self.out_max}")

    def reset(self) -> None:
        self.integral = 0.0
        self._last = None
        self._inputs = None

    def track(self, applied: float) -> None:
        """Back-calculate the integral so the last update would have output ``applied``.

        For when someone else drives the actuator (a policy under DAgger, a human who took
        over): the integral follows what was really applied instead of winding up, and
        handing control back is bumpless.
        """
        if not self.ki or self._inputs is None:
            return
        error, rate = self._inputs
        self.integral = (applied - self.bias - self.kp * error + self.kd * rate) / self.ki
        limit = (self.out_max - self.out_min) / abs(self.ki)
        self.integral = max(-limit, min(limit, self.integral))

    def __call__(
        self, setpoint: float, measurement: float, dt: float, rate: float | None = None
    ) -> float:
        """One update. ``rate`` is the measurement's time derivative if known (e.g. a body
        rate from the sensors); otherwise it is differenced from the last measurement."""
        if not dt > 0:
            raise ConfigError(f"PID dt must be > 0 seconds, got {dt!r}")
        error = setpoint - measurement
        if rate is None:
            rate = 0.0 if self._last is None else (measurement - self._last) / dt
        self._last = measurement
        self._inputs = (error, rate)
        unclamped = self.bias + self.kp * error + self.ki * self.integral - self.kd * rate
        pushing_up = unclamped >= self.out_max and error > 0
        pushing_down = unclamped <= self.out_min and error < 0
        if self.ki and not (pushing_up or pushing_down):
            self.integral += error * dt
            limit = (self.out_max - self.out_min) / abs(self.ki)
            self.integral = max(-limit, min(limit, self.integral))
        out = self.bias + self.kp * error + self.ki * self.integral - self.kd * rate
        return max(self.out_min, min(self.out_max, out))
