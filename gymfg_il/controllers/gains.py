"""Gain sets per aircraft, tuned on JSBSim 1.3.3 at each aircraft's cruise profile.

The inner loops were chosen by a sweep over seeded altitude and heading episodes at 10 Hz,
ranked by success and then by smoothness (mean |change| of the surface per step): higher
pitch gains reach targets too, but make the elevator chatter at this sample rate.

Angles are in degrees, rates in deg/s, speeds in kt and ft/s. Aircraft without their own set
use ``GENERIC`` (a light-aircraft set).
"""

from __future__ import annotations

from dataclasses import dataclass, replace


@dataclass(frozen=True)
class Gains:
    """Gains and limits of the autopilot loops.

    Attributes:
        pitch: (kp, ki, kd) elevator from pitch error (per deg, kd per deg/s of pitch rate).
        roll: (kp, ki, kd) aileron from roll error (kd per deg/s of roll rate).
        climb: (kp, ki, kd) pitch target (deg) from climb-rate error (ft/s).
        altitude_to_climb: climb-rate target (ft/s) per ft of altitude error.
        heading_to_roll: roll target (deg) per deg of heading error.
        speed: (kp, ki, kd) throttle from airspeed error (per kt).
        sideslip: rudder per deg of sideslip (drives sideslip to zero in coordinated flight).
        slip: (kp, ki, kd) rudder from the error to a sideslip target (kd per deg/s of yaw
            rate), for the sideslip task.
        max_pitch_deg, max_roll_deg: attitude limits of the outer loops.
        max_climb_fps, max_descent_fps: climb-rate limits of the altitude loop.
    """

    pitch: tuple[float, float, float]
    roll: tuple[float, float, float]
    climb: tuple[float, float, float]
    altitude_to_climb: float
    heading_to_roll: float
    speed: tuple[float, float, float]
    sideslip: float
    slip: tuple[float, float, float]
    max_pitch_deg: float
    max_roll_deg: float
    max_climb_fps: float
    max_descent_fps: float


GAINS: dict[str, Gains] = {
    "c172p": Gains(
        pitch=(0.04, 0.01, 0.01),
        roll=(0.02, 0.01, 0.01),
        climb=(0.5, 0.1, 0.0),
        altitude_to_climb=0.12,
        heading_to_roll=1.2,
        speed=(0.05, 0.01, 0.0),
        sideslip=0.05,
        slip=(0.05, 0.05, 0.0),
        max_pitch_deg=15.0,
        max_roll_deg=25.0,
        max_climb_fps=15.0,
        max_descent_fps=15.0,
    ),
    "f15": Gains(
        pitch=(0.04, 0.01, 0.01),
        roll=(0.02, 0.01, 0.01),
        climb=(0.15, 0.03, 0.0),
        altitude_to_climb=0.12,
        heading_to_roll=1.2,
        speed=(0.02, 0.004, 0.0),
        sideslip=0.05,
        slip=(0.05, 0.05, 0.0),
        max_pitch_deg=15.0,
        max_roll_deg=30.0,
        max_climb_fps=40.0,
        max_descent_fps=40.0,
    ),
    "A320": Gains(
        pitch=(0.04, 0.01, 0.01),
        roll=(0.02, 0.01, 0.02),
        climb=(0.15, 0.03, 0.0),
        altitude_to_climb=0.1,
        heading_to_roll=1.0,
        speed=(0.03, 0.006, 0.0),
        sideslip=0.05,
        slip=(0.05, 0.05, 0.0),
        max_pitch_deg=12.0,
        max_roll_deg=25.0,
        max_climb_fps=30.0,
        max_descent_fps=30.0,
    ),
}
GENERIC = GAINS["c172p"]
# Where the maneuvers need other loops than the target tasks. A jet's roll loop with the
# target tasks' integral overshoots the bank it is asked for and, in a formation turn, sets
# the slot swinging from side to side: half the integral holds it (a moving roll target needs
# the whole, so the target tasks keep theirs). At 400 kt the f15 must also hold a heading to
# a fraction of a degree to pass a gate or keep a slot: it banks 2 deg per deg of error.
# Both jets also climb on a firmer loop in a maneuver (less overshoot of a new altitude); the
# target tasks keep the gains their cloned policies were measured with (docs/results).
MANEUVER_ROLL = (0.02, 0.005, 0.015)
MANEUVER_CLIMB = (0.3, 0.1, 0.0)
MANEUVER_GAINS: dict[str, Gains] = {
    "f15": replace(GAINS["f15"], roll=MANEUVER_ROLL, climb=MANEUVER_CLIMB, heading_to_roll=2.0),
    "A320": replace(GAINS["A320"], roll=MANEUVER_ROLL, climb=MANEUVER_CLIMB, heading_to_roll=1.5),
}


def gains_for(model: str) -> Gains:
    """The gain set for a JSBSim model (the generic one when it has none of its own)."""
    return GAINS.get(model, GENERIC)


def maneuver_gains(model: str, bank_deg: float) -> Gains:
    """The gain set a maneuver flies ``model`` with: ``MANEUVER_GAINS``' where it has one,
    else the model's, banked at most ``bank_deg`` (its profile's ``bank_deg``)."""
    return replace(MANEUVER_GAINS.get(model) or gains_for(model), max_roll_deg=bank_deg)
