"""The ManualController: a person's keyboard, mouse, joystick or FlightGear cockpit as an Agent.

The session loop hands it each frame's pygame events (``handle``); ``act`` returns the
controls as they stand. Keyboard and joystick state is built from events (KEYDOWN/KEYUP,
JOYAXISMOTION, ...), never from polling, so injected events drive it exactly like real ones.
The ``flightgear`` device reads FlightGear's controls stream instead (``flightgear.cockpit``),
at every ``handle`` and ``act``.

The stick's neutral is the trim: the episode's start controls (``start_from``: a trimmed
start's trim), moved by the trim keys (elevator and rudder) as a real trim wheel moves a
stick's neutral: released keys centre the surfaces on it, the mouse pointer and the joystick
deflect from it with their full travel (``bindings.deflect``: full stick either way is the
full command), and the centre key returns to it. The action is the whole command, so a
hands-off pilot flies the trim.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.manual.bindings import (
    FlightGearBindings,
    JoystickBindings,
    KeyboardBindings,
    MouseBindings,
    deflect,
)
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW

if TYPE_CHECKING:
    from gymfg_il.flightgear.cockpit import CockpitReceiver

DEVICES = ("keyboard", "mouse", "joystick", "flightgear")


def _index(*bound: tuple[list[str], int, float]) -> dict[str, tuple[int, float]]:
    """key name -> (control index, direction), from (key names, index, direction) rows."""
    return {name: (idx, sign) for names, idx, sign in bound for name in names}


def _pg() -> Any:
    import pygame

    return pygame


class ManualController:
    """Agent flown by a person through pygame.

    Args:
        device: ``keyboard``, ``mouse`` (stick from the pointer, throttle and rudder on the
            keyboard), ``joystick`` or ``flightgear`` (FlightGear's own cockpit, its controls
            read from ``--native-ctrls``; the keyboard only runs the session).
        keyboard, mouse, joystick: the bindings (defaults: FlightGear-like).
        flightgear: where FlightGear's controls arrive (``FlightGearBindings``).
        throttle: throttle at the start of each episode.
        window_size: the window the mouse stick is centred in.
    """

    def __init__(
        self,
        device: str = "keyboard",
        keyboard: KeyboardBindings | None = None,
        mouse: MouseBindings | None = None,
        joystick: JoystickBindings | None = None,
        throttle: float = 0.7,
        window_size: tuple[int, int] = (900, 700),
        flightgear: FlightGearBindings | None = None,
    ) -> None:
        if device not in DEVICES:
            raise ConfigError(f"device={device!r}: choose one of {', '.join(DEVICES)}")
        self.device = device
        self.keys = keyboard or KeyboardBindings()
        self.mouse = mouse or MouseBindings()
        self.joy = joystick or JoystickBindings()
        self.start_throttle = throttle
        self.window_size = window_size
        self.values = np.array([0.0, 0.0, 0.0, throttle])
        self.start_controls = self.values.copy()  # this episode's (a trimmed start's trim)
        self.neutral: np.ndarray = np.zeros(3)  # the surfaces' neutral: the start controls
        # the keys held down, in the order they were pressed (a dict as an ordered set): the
        # contributions of keys on one axis add up in that order, the same in every process
        # (a set's order follows string hashes, which PYTHONHASHSEED varies)
        self.held: dict[str, None] = {}
        self.joysticks: dict[int, Any] = {}  # instance id -> pygame Joystick (or None)
        self.status = ""
        k = self.keys
        self._key_of = _index(
            (k.aileron_left, 0, -1.0),
            (k.aileron_right, 0, 1.0),
            (k.elevator_down, 1, 1.0),
            (k.elevator_up, 1, -1.0),
            (k.rudder_left, 2, -1.0),
            (k.rudder_right, 2, 1.0),
            (k.throttle_up, 3, 1.0),
            (k.throttle_down, 3, -1.0),
        )
        self._trim_of = _index(
            (k.trim_nose_down, 1, 1.0),
            (k.trim_nose_up, 1, -1.0),
            (k.trim_rudder_left, 2, -1.0),
            (k.trim_rudder_right, 2, 1.0),
        )
        self.cockpit: CockpitReceiver | None = None
        if device == "flightgear":
            from gymfg_il.flightgear.cockpit import CockpitReceiver

            fg = flightgear or FlightGearBindings()
            self.cockpit = CockpitReceiver(fg.port, fg.host)
            self.status = f"flightgear: waiting for controls on {fg.host}:{fg.port}"

    # -- Agent ---------------------------------------------------------------------------
    def reset(self, seed: int | None = None) -> None:
        self._start(np.array([0.0, 0.0, 0.0, self.start_throttle]))

    def start_from(self, action: np.ndarray) -> None:
        """Hold the aircraft's start controls (a trimmed start's trim) until the pilot moves."""
        self._start(np.array(action, dtype=np.float64))

    def _start(self, values: np.ndarray) -> None:
        self.values = values
        self.start_controls = values.copy()
        self.neutral = values[:3].copy()
        self.held.clear()
        if self.cockpit is not None:  # FlightGear's stick stays where the person holds it
            self.cockpit.poll()
            if self.cockpit.latest is not None:
                self.values[:] = self.cockpit.latest

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        if self.cockpit is not None:
            self._cockpit()
        return self.values.copy()

    def _cockpit(self) -> None:
        assert self.cockpit is not None
        values = self.cockpit.poll()
        if values is not None:
            self.values[:] = values
            self.status = "flightgear: flying from FlightGear's cockpit"
        elif self.cockpit.received and self.cockpit.silent_s > 1.0:
            self.status = "flightgear: no controls for over a second; is fgfs still running?"

    def close(self) -> None:
        if self.cockpit is not None:
            self.cockpit.close()

    def set_throttle(self, throttle: float) -> None:
        self.values[3] = throttle

    # -- input ---------------------------------------------------------------------------
    def handle(self, events: Iterable[Any], dt: float) -> list[str]:
        """Apply one frame of events; returns session commands from joystick buttons."""
        pg = _pg()
        commands: list[str] = []
        for ev in events:
            if ev.type == pg.KEYDOWN:
                self.held.setdefault(pg.key.name(ev.key))
                if pg.key.name(ev.key) in self.keys.center:
                    self.values[:3] = self.neutral
            elif ev.type == pg.KEYUP:
                self.held.pop(pg.key.name(ev.key), None)
            elif ev.type == pg.MOUSEMOTION and self.device == "mouse":
                self._mouse(ev.pos)
            elif self.device == "joystick":
                commands += self._joystick_event(pg, ev)
        if self.cockpit is not None:
            self._cockpit()
        else:
            self._keyboard(dt, surfaces=self.device == "keyboard")
        return commands

    def _keyboard(self, dt: float, surfaces: bool) -> None:
        k = self.keys
        moved = [False] * 4
        for name in self.held:
            trim = self._trim_of.get(name)
            if trim is not None:  # the neutral moves, and the surface with it
                idx, sign = trim
                old = self.neutral[idx]
                self.neutral[idx] = np.clip(old + sign * k.trim_rate * dt, -1.0, 1.0)
                self.values[idx] += self.neutral[idx] - old
            hit = self._key_of.get(name)
            if hit is None:
                continue
            idx, sign = hit
            if idx < 3 and not surfaces and not (self.device == "mouse" and idx == 2):
                continue
            if (
                idx == 3
                and self.device == "joystick"
                and "throttle" in self.joy.axes
                and self.joysticks
            ):
                continue
            rate = k.throttle_rate if idx == 3 else k.rate
            self.values[idx] += sign * rate * dt
            moved[idx] = True
        if k.centering:
            step = k.centering * dt
            for idx in range(3):
                keyboard_axis = surfaces or (self.device == "mouse" and idx == 2)
                if keyboard_axis and not moved[idx]:
                    off = self.values[idx] - self.neutral[idx]
                    off = 0.0 if abs(off) <= step else off - step * np.sign(off)
                    self.values[idx] = self.neutral[idx] + off
        np.clip(self.values, ACTION_LOW, ACTION_HIGH, out=self.values)

    def _mouse(self, pos: tuple[int, int]) -> None:
        m = self.mouse
        cx, cy = self.window_size[0] / 2, self.window_size[1] / 2
        x = (pos[0] - cx) / m.span_px
        y = -(pos[1] - cy) / m.span_px  # pointer up = stick forward = nose down (+elevator)
        if m.invert_elevator:
            y = -y
        for idx, v in ((0, x), (1, y)):
            v = max(-1.0, min(1.0, v))
            v = 0.0 if abs(v) < m.dead_zone else v
            self.values[idx] = deflect(self.neutral[idx], v)

    def _joystick_event(self, pg: Any, ev: Any) -> list[str]:
        if ev.type == pg.JOYDEVICEADDED:
            try:
                stick = pg.joystick.Joystick(ev.device_index)
                self.joysticks[stick.get_instance_id()] = stick
                self.status = f"joystick: {stick.get_name()}"
            except (pg.error, AttributeError):  # an injected event: no device behind it
                self.joysticks[getattr(ev, "instance_id", ev.device_index)] = None
                self.status = "joystick connected"
        elif ev.type == pg.JOYDEVICEREMOVED:
            self.joysticks.pop(ev.instance_id, None)
            if not self.joysticks:
                self.values[:3] = self.neutral  # no stick, no deflection; throttle stays
                self.status = "joystick unplugged: surfaces centred, plug it back in"
        elif ev.type == pg.JOYAXISMOTION:
            for control, axis in self.joy.axes.items():
                if axis == ev.axis:
                    idx = ("aileron", "elevator", "rudder", "throttle").index(control)
                    value = self.joy.shape(control, ev.value)
                    if idx < 3:  # a surface deflects from its neutral; the throttle is absolute
                        value = deflect(self.neutral[idx], max(-1.0, min(1.0, value)))
                    self.values[idx] = value
        elif ev.type == pg.JOYBUTTONDOWN:
            command = self.joy.buttons.get(ev.button)
            if command == "center":
                self.values[:3] = self.neutral
            elif command:
                return [command]
        return []
