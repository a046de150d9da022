"""What a pilot who sees only the window wants the controls to be.

A person at the collector's window has the display model (``display.readings``): the
instruments, the targets as bugs and the task's guidance, nothing else; no observation
vector, no integral, no body rate. ``DisplayIntent`` is the intent of the synthetic pilot:
the task's expert loops (``controllers.autopilot``, flown with a person's hands on that
aircraft: ``Hands``, ``hands_of``), fed only with readings the window draws, and with the
two rates a person reads from the moving attitude indicator (how fast the horizon rolls and
pitches). Each task's targets are taken from its bugs and guidance, where its expert says
(``tasks.experts.Expert.on_display``); a reading the window does not draw cannot be read:
building the intent for a task fails if its loops need one.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from gymfg_il.controllers.autopilot import Autopilot, controller_for
from gymfg_il.controllers.gains import Gains
from gymfg_il.display.readings import Display
from gymfg_il.moved import forward_names
from gymfg_il.tasks.guidance import reading_names
from gymfg_il.units import DEG_TO_RAD, wrap_180

# the rates the eye reads off the attitude indicator's motion: rate -> the reading it moves
MOTION = {"p_rad_s": "roll_deg", "q_rad_s": "pitch_deg"}
ANGLES = {"heading_deg", "heading_deg_target", "gate_bearing_deg", "lead_heading_deg"}
ANGLES |= {"runway_course_deg", "roll_deg", "lead_roll_deg"}


@dataclass(frozen=True)
class Hands:
    """How a person flies the expert's loops on one aircraft (``hands_of``).

    Attributes:
        pitch_damping: share of the expert's pitch-rate gain (a person reads the pitch rate
            off the moving horizon, late and imprecisely, where an autopilot has a gyro).
        slip_gain: share of the expert's slip gains, the integral's half of that (keyboard
            taps held against a P+I slip loop chatter past the tolerance).
        station: share of the expert's station-keeping gains (how hard it chases a formation
            slot; with the expert's, its quarter-second delay made it surge past and fall back).
        anticipate: how far it leads a moving reading, as a share of its delay
            (``manual.synthetic``): a person leads an agile aircraft, whose attitude moves
            within its reaction time, and not a slow one, whose readings it would only shake.
        slot_ahead_ft: how far ahead of a formation slot it keeps station. On an aircraft
            with little power to spare a wingman sits a little ahead: dropping back takes a
            touch of power, catching up full power for many seconds (on the outside of the
            lead's turn, none is left).
        slot_track: share of the expert's gain towards a formation slot's side line (with
            the expert's, the c172p's pilot chased it in +-30 deg banks, turning away from a
            lead that rolled the other way).
        slot_throttle_floor: the least throttle it sets in formation: a wingman works the
            power in small changes; at idle a c172p loses 10 kt in a few seconds and needs
            many more to win them back (BC from its pilot learnt such cuts and fell behind).
    """

    pitch_damping: float = 0.5
    slip_gain: float = 0.4
    station: float = 0.5
    anticipate: float = 0.0
    slot_ahead_ft: float = 0.0
    slot_track: float = 1.0
    slot_throttle_floor: float = 0.0


# tuned on seeds 100-163 (docs/results/cockpit.md); an aircraft not named flies with Hands()
HANDS: dict[str, Hands] = {
    "f15": Hands(anticipate=0.5),
    "c172p": Hands(slot_ahead_ft=30.0, slot_track=0.5, slot_throttle_floor=0.4),
}


def hands_of(gains: Gains, hands: Hands) -> Gains:
    """The expert's gains as a person's ``hands`` fly them (``Hands``)."""
    kp, ki, kd = gains.pitch
    skp, ski, skd = gains.slip
    slip = hands.slip_gain
    return dataclasses.replace(
        gains, pitch=(kp, ki, kd * hands.pitch_damping), slip=(skp * slip, ski * slip / 2, skd)
    )


class DisplayIntent:
    """The controls a pilot looking at ``task``'s window wants (module docstring).

    Args:
        task: the bound Task being flown.
        model: the aircraft's JSBSim model (its gain set).
        dt: seconds per agent step.
        throttle: the aircraft's cruise throttle.

    ``look(display)`` turns one frame's display into what the pilot reads (``names``, in
    order: the readings, then the rates of ``MOTION``); ``act(seen)`` gives the controls.
    """

    def __init__(self, task: Any, model: str, dt: float, throttle: float) -> None:
        expert = controller_for(task, model, dt, throttle)
        declared = task.expert()  # not None: the task has an expert to build
        targets = dataclasses.replace(expert.targets, **declared.on_display)
        self.hands = HANDS.get(model, Hands())
        kp, kd = targets.station_gains
        station = (kp * self.hands.station, kd * self.hands.station)
        targets = dataclasses.replace(targets, station_gains=station)
        if targets.station_source is not None:  # a slot's side line, not a runway's
            track = targets.track_gain * self.hands.slot_track
            targets = dataclasses.replace(targets, track_gain=track)
        self.readings = reading_names(task)
        self.names = (*self.readings, *MOTION)
        self.angular = np.array([n in ANGLES for n in self.names])
        self.dt = dt
        gains = hands_of(expert.gains, self.hands)
        self.autopilot = Autopilot(self.names, model, dt, targets, gains=gains)
        self.autopilot.set_throttle_trim(throttle)
        if targets.station_source is not None:
            self.autopilot.speed_pid.out_min = self.hands.slot_throttle_floor
        self._last: dict[str, float] | None = None

    @property
    def used(self) -> set[str]:
        """The display's readings the loops read (the rates count as their attitude's)."""
        names = set(self.autopilot.needs)
        return {MOTION.get(n, n) for n in names}

    def reset(self, seed: int | None = None) -> None:
        self.autopilot.reset(seed)
        self._last = None

    def start_from(self, action: np.ndarray) -> None:
        self.autopilot.start_from(action)

    def look(self, display: Display) -> np.ndarray:
        """What the pilot reads off one frame (``names`` order)."""
        shown = {r.name: r.value for r in display}
        values = [shown[name] for name in self.readings]
        last, self._last = self._last, shown
        for angle in MOTION.values():
            moved = 0.0 if last is None else wrap_180(shown[angle] - last[angle])
            values.append(moved / self.dt * DEG_TO_RAD)
        return np.array(values, dtype=np.float64)

    def act(self, seen: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        if self.hands.slot_ahead_ft and "behind_slot_ft" in self.names:
            seen = seen.copy()
            seen[self.names.index("behind_slot_ft")] += self.hands.slot_ahead_ft
        return self.autopilot.act(seen)


# a table whose knowledge each task now declares itself
__getattr__ = forward_names(
    __name__,
    {},
    gone={"DISPLAY_SOURCES": "each task's expert declares it: Task.expert().on_display"},
)
