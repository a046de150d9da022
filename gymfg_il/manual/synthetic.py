"""A synthetic human pilot: a model of a person flying through the real ManualController.

It decides, frame by frame, the pygame events a person at the controls would produce: keys
pressed and released, joystick axes moved, the mouse dragged. It sees only what the window
draws (the display model, ``display.readings``); what it wants to do with that comes from the
task's expert loops fed with those readings (its "intent", ``manual.perception``: a competent
pilot knows what the aircraft needs); how it gets there is human:

- it reacts to what it saw ``reaction_s`` ago; on an agile aircraft it leads what it saw as
  a person leads a moving needle, extrapolating each reading's trend over the last
  ``TREND_S`` by its hands' ``anticipate`` share of its delay (``manual.perception.Hands``;
  without it the delay made the f15's formation loops weave off the slot);
- it reads the instruments imprecisely: its misreadings drift smoothly over about a second,
  in proportion to how lively each reading has been over that second;
- on the keyboard it can only hold keys: it presses one when the stick is off what it wants by
  more than its ``deadband``, and lets go only once the stick has passed the mark by its
  ``overshoot`` (over-corrections), while the controller's centring pulls the stick back;
- a joystick or mouse hand shakes (``tremor``) and a stick reads in steps (``quantum``);
- now and then its attention lapses: for ``lapse_s`` it lets go of the keys and holds still;
- on the keyboard it trims: when the elevator or rudder it has wanted over the last few
  seconds (``TRIM_S``) sits off the trim by more than ``TRIM_BAND``, it holds the trim key
  until the trim passes it (the trim ticks are drawn beside the stick), so a steady
  deflection needs no key held.

``Skill.of(level)`` sets all of these from one number, 0 (a novice) to 1 (an ace). The same
seed makes the same pilot make the same mistakes, so its demonstrations reproduce.

It flies through the real session loop (``collect manual --pilot synthetic``: its events are
the session's input, ``cockpit.inputs.synthetic_pilot``) or as an Agent (``PilotAgent``: its
events go straight to a ManualController), so evaluation can score it beside the controller
and the policies.
"""

from __future__ import annotations

import collections
import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.display.readings import Display
from gymfg_il.errors import ConfigError
from gymfg_il.manual.bindings import (
    JoystickBindings,
    KeyboardBindings,
    MouseBindings,
    deflection,
)
from gymfg_il.manual.controller import DEVICES, ManualController
from gymfg_il.manual.perception import DisplayIntent
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW
from gymfg_il.units import wrap_180

CONTROLS = ("aileron", "elevator", "rudder", "throttle")
MISREAD_S = 1.0  # how long a reading error lasts (the time constant of its drift)
SMOOTHED = float(np.sqrt(2.0))  # the drift's std is the misread's over sqrt(2): restore it
TREND_S = 0.2  # over how long it judges a reading's trend (to lead it)
TRIM_S = 3.0  # over how long the pilot judges the steady deflection it trims out
TRIM_BAND = 0.02  # how far the trim may sit off that deflection before it trims
TRIMMED = (1, 2)  # the surfaces with trim keys: elevator, rudder


@dataclass(frozen=True)
class Skill:
    """How a synthetic pilot flies (see the module docstring).

    Attributes:
        reaction_s: how long after something happens the pilot responds to it.
        perception: std of its reading error, as a share of each instrument's value change
            over one second (0 reads perfectly).
        deadband: stick error it lets pass before correcting (keyboard), control units.
        overshoot: how far past the wanted position a key is held (keyboard).
        tremor: std of its hand's shake on a joystick or mouse, control units.
        quantum: the stick's resolution, control units.
        lapse_per_min: how often its attention lapses.
        lapse_s: how long a lapse lasts.
    """

    reaction_s: float
    perception: float
    deadband: float
    overshoot: float
    tremor: float
    quantum: float
    lapse_per_min: float
    lapse_s: float

    @classmethod
    def of(cls, level: float) -> Skill:
        """A pilot of ``level`` in [0, 1]: 0 a novice, 1 an ace."""
        if not (isinstance(level, (int, float)) and 0.0 <= level <= 1.0):
            raise ConfigError(f"skill={level!r} must lie in [0, 1] (0 a novice, 1 an ace)")
        x = float(level)
        return cls(
            reaction_s=0.5 - 0.35 * x,
            perception=0.3 * (1.0 - x),
            deadband=0.06 - 0.04 * x,
            overshoot=0.03 - 0.02 * x,
            tremor=0.03 * (1.0 - x) + 0.003,
            quantum=1.0 / 128.0,
            lapse_per_min=4.0 * (1.0 - x),
            lapse_s=1.5 - x,
        )


def _event(kind: str, **fields: Any) -> Any:
    import pygame

    return pygame.event.Event(getattr(pygame, kind), **fields)


@functools.cache
def key_codes() -> dict[str, int]:
    """pygame's key code of each key name (``pygame.key.key_code`` wants pygame.init())."""
    import pygame

    codes = (getattr(pygame, n) for n in dir(pygame) if n.startswith("K_"))
    return {pygame.key.name(code): code for code in codes}


class SyntheticPilot:
    """The events a person would produce at the controls (see the module docstring).

    Args:
        device: keyboard, joystick or mouse.
        intent: what the pilot wants the controls to be, from what the window shows
            (``manual.perception.DisplayIntent``).
        dt: seconds per frame.
        skill: ``Skill`` or a level in [0, 1].
        keyboard, mouse, joystick: the session's bindings (which keys, axes, spans).
        window_size: the window the mouse stick is centred in.
        seed: the pilot's own randomness (reading errors, tremor, lapses).
    """

    def __init__(
        self,
        device: str,
        intent: DisplayIntent,
        dt: float,
        skill: Skill | float = 0.7,
        keyboard: KeyboardBindings | None = None,
        mouse: MouseBindings | None = None,
        joystick: JoystickBindings | None = None,
        window_size: tuple[int, int] = (900, 700),
        seed: int = 0,
    ) -> None:
        if device not in DEVICES:
            raise ConfigError(f"device={device!r}: choose one of {', '.join(DEVICES)}")
        self.device, self.intent, self.dt = device, intent, dt
        self.skill = skill if isinstance(skill, Skill) else Skill.of(skill)
        self.keys = keyboard or KeyboardBindings()
        self.mouse = mouse or MouseBindings()
        self.joy = joystick or JoystickBindings()
        self.window_size = window_size
        grid = np.linspace(-1.0, 1.0, 401)
        self._aims: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        for control in self.joy.axes:  # the axis position that gives each control value
            shaped = np.array([self.joy.shape(control, x) for x in grid])
            order = np.argsort(shaped, kind="stable")
            self._aims[control] = (shaped[order], grid[order])
        self._key_names = {
            0: (self.keys.aileron_left[0], self.keys.aileron_right[0]),
            1: (self.keys.elevator_up[0], self.keys.elevator_down[0]),  # nose up = -elevator
            2: (self.keys.rudder_left[0], self.keys.rudder_right[0]),
            3: (self.keys.throttle_down[0], self.keys.throttle_up[0]),
        }
        self._trim_names = {
            1: (self.keys.trim_nose_up[0], self.keys.trim_nose_down[0]),
            2: (self.keys.trim_rudder_left[0], self.keys.trim_rudder_right[0]),
        }
        self.reset(seed)

    # -- episode ---------------------------------------------------------------------------
    def reset(self, seed: int | None = None) -> None:
        self.rng = np.random.default_rng([0 if seed is None else seed, 104729])
        self.intent.reset(seed)
        delay = max(1, round(self.skill.reaction_s / self.dt))
        self._delay, self._trend = delay, max(1, round(TREND_S / self.dt))
        self._anticipate = getattr(getattr(self.intent, "hands", None), "anticipate", 0.0)
        self._seen: collections.deque[np.ndarray] = collections.deque(maxlen=delay + self._trend)
        self._held: dict[int, int] = {}  # control index -> direction (+1 / -1) of the key held
        self._axes: dict[int, float] = {}  # joystick axis -> the value last sent
        self._pointer: tuple[int, int] | None = None
        self._lapse_left = 0.0
        self._last_obs: np.ndarray | None = None
        self._misread: np.ndarray | None = None  # each reading's error, in its own stds
        self._drift = np.zeros(0)  # the misread, smoothed: what the pilot's reading is off by
        self._lively = np.zeros(0)  # each reading's change per second, over about a second
        self._plugged = False
        self.neutral: np.ndarray = np.zeros(3)  # the stick's neutral (start_from moves it)
        self._trimming: dict[int, int] = {}  # control index -> direction of the trim key held
        self._steady: np.ndarray | None = None  # the deflection wanted over the last TRIM_S
        self.sent: list[Any] = []
        self.pressed: list[tuple[str, bool]] = []  # (key, down) this frame, for the record

    # -- deciding --------------------------------------------------------------------------
    def _perceive(self, display: Display) -> np.ndarray:
        """What the pilot reads off the window, ``reaction_s`` late and imprecisely."""
        read = self.intent.look(display)
        obs = read
        if self._misread is None:
            self._misread = np.zeros(len(read))
            self._drift = np.zeros(len(read))
            self._lively = np.zeros(len(read))
        if self.skill.perception and self._last_obs is not None:
            change = read - self._last_obs
            change[self.intent.angular] = wrap_180(change[self.intent.angular])
            # how lively each reading is: its change over about the last second (a jerk of
            # one frame does not make the pilot misread it more)
            keep = np.exp(-self.dt / MISREAD_S)
            self._lively = keep * self._lively + (1.0 - keep) * np.abs(change) / self.dt
            # a misjudgement drifts smoothly over about a second; it neither flickers frame by
            # frame nor jerks (a loop that differences a reading would take the jerks for rates)
            fresh = self.rng.normal(0.0, 1.0, len(read)) * np.sqrt(1.0 - keep * keep)
            self._misread = keep * self._misread + fresh
            self._drift = keep * self._drift + (1.0 - keep) * self._misread
            obs = read + SMOOTHED * self._drift * self.skill.perception * self._lively
        self._last_obs = read
        self._seen.append(obs)
        seen = self._seen[max(0, len(self._seen) - self._delay)]
        older = len(self._seen) - self._delay - self._trend
        if not self._anticipate or older < 0:
            return seen
        # a person leads a moving reading: it extrapolates what it saw by its own delay
        trend = seen - self._seen[older]
        trend[self.intent.angular] = wrap_180(trend[self.intent.angular])
        return seen + self._anticipate * trend * (self._delay / self._trend)

    def _lapsing(self) -> bool:
        if self._lapse_left > 0:
            self._lapse_left -= self.dt
            return True
        chance = self.skill.lapse_per_min * self.dt / 60.0
        if self.rng.random() < chance:
            self._lapse_left = self.skill.lapse_s
            return True
        return False

    def start_from(self, action: np.ndarray) -> None:
        """The aircraft's start controls (a trimmed start's trim): the intent starts from
        them and the stick's neutral is there (``ManualController``)."""
        self.neutral = np.array(action[:3], dtype=np.float64)
        start = getattr(self.intent, "start_from", None)
        if start is not None:
            start(action)

    def events(self, display: Display, stick: np.ndarray) -> list[Any]:
        """This frame's events, from what the window shows and the controls as they stand
        (also kept as ``sent``; the keys among them as ``pressed``: (name, down)). The mouse
        and the joystick aim at the wanted controls less the stick's neutral."""
        self.pressed = []
        seen = self._perceive(display)
        want = np.clip(np.asarray(self.intent.act(seen), dtype=np.float64), ACTION_LOW, ACTION_HIGH)
        out: list[Any] = []
        if self.device == "joystick" and not self._plugged:
            out.append(_event("JOYDEVICEADDED", device_index=0, instance_id=0))
            self._plugged = True
        if self._lapsing():
            out += self._let_go()
        elif self.device == "keyboard":
            out += self._keyboard(want, stick, range(4)) + self._trim(want)
        elif self.device == "mouse":  # the pointer is the stick; rudder and throttle are keys
            out += self._mouse(want) + self._keyboard(want, stick, (2, 3))
        else:
            out += self._joystick(want)
        self.sent = out
        return out

    def _key(self, name: str, down: bool) -> Any:
        self.pressed.append((name, down))
        kind = "KEYDOWN" if down else "KEYUP"
        return _event(kind, key=key_codes()[name], mod=0, unicode="", scancode=0)

    def _let_go(self) -> list[Any]:
        out = [self._key(self._key_names[i][(d + 1) // 2], False) for i, d in self._held.items()]
        out += [
            self._key(self._trim_names[i][(d + 1) // 2], False) for i, d in self._trimming.items()
        ]
        self._held.clear()
        self._trimming.clear()
        return out

    def _trim(self, want: np.ndarray) -> list[Any]:
        """Trim out the steady deflection: hold a trim key while the deflection wanted over
        the last ``TRIM_S`` sits off the trim by ``TRIM_BAND``, until the trim passes it.
        The trim moves as the ManualController moves it (``trim_rate`` while held)."""
        keep = np.exp(-self.dt / TRIM_S)
        wanted = want[:3]
        self._steady = (
            wanted.copy() if self._steady is None else keep * self._steady + (1 - keep) * wanted
        )
        out = []
        for i in TRIMMED:
            held = self._trimming.get(i)
            error = float(self._steady[i] - self.neutral[i])
            if held is None and abs(error) > TRIM_BAND:
                self._trimming[i] = 1 if error > 0 else -1
                out.append(self._key(self._trim_names[i][(self._trimming[i] + 1) // 2], True))
            elif held is not None and held * error <= 0:
                del self._trimming[i]
                out.append(self._key(self._trim_names[i][(held + 1) // 2], False))
        step = self.keys.trim_rate * self.dt
        for i, held in self._trimming.items():  # the controller moves it this frame
            self.neutral[i] = np.clip(self.neutral[i] + held * step, -1.0, 1.0)
        return out

    def _keyboard(self, want: np.ndarray, stick: np.ndarray, controls: Any) -> list[Any]:
        """Hold a key while the stick is off the mark; let go once it is past the mark."""
        skill, out = self.skill, []
        for i in controls:
            error = float(want[i] - stick[i])
            held = self._held.get(i)
            if held is None:
                if abs(error) > skill.deadband:
                    direction = 1 if error > 0 else -1
                    self._held[i] = direction
                    out.append(self._key(self._key_names[i][(direction + 1) // 2], True))
            elif held * error < -skill.overshoot:  # passed the mark by the overshoot
                del self._held[i]
                out.append(self._key(self._key_names[i][(held + 1) // 2], False))
        return out

    def _joystick(self, want: np.ndarray) -> list[Any]:
        out = []
        for control, axis in self.joy.axes.items():
            i = CONTROLS.index(control)
            aim = deflection(self.neutral[i], float(want[i])) if i < 3 else float(want[i])
            raw = self._raw(control, aim + self.rng.normal(0.0, self.skill.tremor))
            raw = round(raw / self.skill.quantum) * self.skill.quantum
            raw = max(-1.0, min(1.0, raw))
            if self._axes.get(axis) != raw:
                self._axes[axis] = raw
                out.append(_event("JOYAXISMOTION", instance_id=0, axis=axis, value=raw))
        return out

    def _raw(self, control: str, wanted: float) -> float:
        """The axis position whose shaped value is ``wanted`` (a person aims by eye; this
        inverts the bindings' dead zone, expo and inversion)."""
        shaped, raw = self._aims[control]
        return float(np.interp(wanted, shaped, raw))

    def _mouse(self, want: np.ndarray) -> list[Any]:
        m = self.mouse
        cx, cy = self.window_size[0] / 2, self.window_size[1] / 2
        x = deflection(self.neutral[0], float(want[0])) + self.rng.normal(0.0, self.skill.tremor)
        y = deflection(self.neutral[1], float(want[1])) + self.rng.normal(0.0, self.skill.tremor)
        if m.invert_elevator:
            y = -y
        pos = (round(cx + x * m.span_px), round(cy - y * m.span_px))
        if pos == self._pointer:
            return []
        self._pointer = pos
        return [_event("MOUSEMOTION", pos=pos, rel=(0, 0), buttons=(0, 0, 0))]


class PilotAgent:
    """A synthetic pilot flying as an Agent: its events go straight to a ManualController,
    whose controls are the action (what ``eval --pilot synthetic`` flies). ``look`` gives
    the display of the moment; the observation an Agent is handed is never read."""

    def __init__(
        self, pilot: SyntheticPilot, human: ManualController, look: Callable[[], Display]
    ) -> None:
        self.pilot, self.human, self.look = pilot, human, look

    def reset(self, seed: int | None = None) -> None:
        self.human.reset(seed)
        self.pilot.reset(seed)

    def start_from(self, action: np.ndarray) -> None:
        self.human.start_from(action)
        self.pilot.start_from(action)

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        events = self.pilot.events(self.look(), self.human.values)
        self.human.handle(events, self.pilot.dt)
        return self.human.act(observation)
