"""Input mappings: which keys, mouse motions and joystick axes move which control.

Defaults follow FlightGear where it has a convention (arrows for elevator and aileron, with Up
pushing the nose down; keypad 0/Enter for rudder; Page Up/Down for throttle; keypad 5 to
centre; Home/End and keypad 7/1 for elevator trim, nose down and nose up). Every field can be
set in a recipe's ``[collector.keyboard]``, ``[collector.mouse]`` or ``[collector.joystick]``
table; keys are pygame key names (``pygame.key.name``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from gymfg_il.errors import ConfigError

CONTROLS = ("aileron", "elevator", "rudder", "throttle")


@dataclass
class KeyboardBindings:
    """Keyboard flying: holding a key moves its control at ``rate`` per second; released
    surfaces return to their neutral (the trim) at ``centering`` per second (0 = they stay).
    Holding a trim key moves the neutral (and the surface with it) at ``trim_rate`` per
    second, so a steady deflection (a slower speed's nose-up elevator, a held sideslip's
    rudder) stays without a key held.

    Attributes:
        aileron_left, aileron_right, elevator_down, elevator_up: key names (several allowed).
        rudder_left, rudder_right, throttle_up, throttle_down: key names (several allowed).
        trim_nose_down, trim_nose_up: elevator trim keys (FlightGear's Home/End, keypad 7/1).
        trim_rudder_left, trim_rudder_right: rudder trim keys (Insert/Delete; FlightGear
            has no plain-key rudder trim).
        center: key that centres the three surfaces at once (on the trim).
        rate: surface travel per second while a key is held (full range = 2).
        throttle_rate: throttle travel per second while a key is held.
        centering: surface return-to-centre speed per second after release (0 = off).
        trim_rate: trim travel per second while a trim key is held.
    """

    aileron_left: list[str] = field(default_factory=lambda: ["left", "[4]"])
    aileron_right: list[str] = field(default_factory=lambda: ["right", "[6]"])
    elevator_down: list[str] = field(default_factory=lambda: ["up", "[8]"])
    elevator_up: list[str] = field(default_factory=lambda: ["down", "[2]"])
    rudder_left: list[str] = field(default_factory=lambda: ["[0]", ","])
    rudder_right: list[str] = field(default_factory=lambda: ["enter", "."])
    throttle_up: list[str] = field(default_factory=lambda: ["page up", "[9]"])
    throttle_down: list[str] = field(default_factory=lambda: ["page down", "[3]"])
    trim_nose_down: list[str] = field(default_factory=lambda: ["home", "[7]"])
    trim_nose_up: list[str] = field(default_factory=lambda: ["end", "[1]"])
    trim_rudder_left: list[str] = field(default_factory=lambda: ["insert"])
    trim_rudder_right: list[str] = field(default_factory=lambda: ["delete"])
    center: list[str] = field(default_factory=lambda: ["[5]", "5"])
    rate: float = 1.5
    throttle_rate: float = 0.5
    centering: float = 1.0
    trim_rate: float = 0.1

    def __post_init__(self) -> None:
        _check_positive(self, ("rate", "throttle_rate", "trim_rate"), allow_zero=("centering",))


@dataclass
class MouseBindings:
    """Mouse flying (the paper's design): the pointer's offset from the window centre is the
    stick (elevator and aileron); throttle and rudder stay on the keyboard.

    Attributes:
        span_px: pointer offset (pixels) that gives full deflection.
        invert_elevator: pointer up = nose up instead of nose down.
        dead_zone: stick fraction around the centre that reads as zero.
    """

    span_px: float = 200.0
    invert_elevator: bool = False
    dead_zone: float = 0.03

    def __post_init__(self) -> None:
        _check_positive(self, ("span_px",), allow_zero=("dead_zone",))


@dataclass
class JoystickBindings:
    """Joystick or gamepad flying.

    Attributes:
        axes: control -> axis number (``{aileron = 0, elevator = 1, rudder = 3, throttle = 2}``).
        invert: controls whose axis is reversed.
        dead_zone: axis magnitude below which the axis reads zero (rescaled outside it).
        expo: 0 = linear, up to 1 = gentle around the centre (``(1-e) x + e x^3``).
        throttle_from_axis: the throttle axis runs -1..1 (lever) and maps to 0..1.
        buttons: button number -> session command (start, end, discard, pause, takeover,
            center).
    """

    axes: dict[str, int] = field(
        default_factory=lambda: {"aileron": 0, "elevator": 1, "rudder": 3, "throttle": 2}
    )
    invert: list[str] = field(default_factory=lambda: ["throttle"])
    dead_zone: float = 0.05
    expo: float = 0.3
    throttle_from_axis: bool = True
    buttons: dict[int, str] = field(default_factory=lambda: {0: "takeover", 1: "center"})

    def __post_init__(self) -> None:
        problems = []
        unknown = [c for c in self.axes if c not in CONTROLS]
        if unknown:
            problems.append(f"axes name unknown controls {unknown}; use {list(CONTROLS)}")
        if any(not isinstance(a, int) or a < 0 for a in self.axes.values()):
            problems.append(f"axis numbers must be integers >= 0, got {self.axes}")
        if not 0.0 <= self.dead_zone < 1.0 or not 0.0 <= self.expo <= 1.0:
            problems.append("dead_zone must lie in [0, 1) and expo in [0, 1]")
        self.buttons = {int(k): v for k, v in self.buttons.items()}
        if problems:
            raise ConfigError("joystick bindings: " + "; ".join(problems))

    def shape(self, control: str, raw: float) -> float:
        """Axis value after inversion, dead zone and expo."""
        x = -raw if control in self.invert else raw
        mag = abs(x)
        if mag <= self.dead_zone:
            return 0.0
        x = math.copysign((mag - self.dead_zone) / (1.0 - self.dead_zone), x)
        x = (1.0 - self.expo) * x + self.expo * x**3
        if control == "throttle" and self.throttle_from_axis:
            return (x + 1.0) / 2.0
        return x


@dataclass
class FlightGearBindings:
    """FlightGear as the cockpit: FlightGear's ``--native-ctrls=socket,out,HZ,HOST,PORT,udp``
    stream gives the controls (FlightGear's own joystick and keyboard bindings apply).

    Attributes:
        port: UDP port FlightGear sends its controls to (the PORT of --native-ctrls).
        host: address to listen on; loopback by default.
    """

    port: int = 5700
    host: str = "127.0.0.1"

    def __post_init__(self) -> None:
        if not (isinstance(self.port, int) and 0 < self.port < 65536):
            raise ConfigError(f"flightgear bindings: port={self.port!r}: want 1..65535")


def _check_positive(obj: object, names: tuple[str, ...], allow_zero: tuple[str, ...] = ()) -> None:
    bad = [f"{n}={getattr(obj, n)!r}" for n in names if not getattr(obj, n) > 0]
    bad += [f"{n}={getattr(obj, n)!r}" for n in allow_zero if not getattr(obj, n) >= 0]
    if bad:
        raise ConfigError(f"{type(obj).__name__}: {', '.join(bad)} must be positive")


def from_table(cls: type, table: dict[str, Any] | None, where: str) -> Any:
    """Bindings from a recipe table; unknown keys are an error naming the known ones."""
    table = dict(table or {})
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise ConfigError(f"{where}: unknown keys {unknown}; known: {sorted(known)}")
    return cls(**table)


def deflect(neutral: float, v: float) -> float:
    """The surface command of a stick (or mouse) deflected by ``v`` in [-1, 1] from its
    ``neutral`` (the trim): full travel either way is the full command, as a trimmed
    aircraft's stick keeps its full travel (trim 0.18: -1 -> -1.0, 0 -> 0.18, +1 -> +1.0)."""
    return neutral + v * (1.0 - neutral if v > 0 else 1.0 + neutral)


def deflection(neutral: float, command: float) -> float:
    """The deflection ``v`` that ``deflect(neutral, v)`` turns into ``command`` (how far a
    pilot aiming at a command moves the stick)."""
    span = 1.0 - neutral if command > neutral else 1.0 + neutral
    return (command - neutral) / span if span > 0 else 0.0
