"""The catalogue of state variables: each JSBSim property declared once, with units and bounds.

Observation names, gymnasium spaces, opponent views, dataset feature names and log schemas are
all derived from ``CATALOGUE``. A state vector is a float64 array in catalogue order; use
``INDEX[name]`` (or ``StateView``) to reach one variable. ``describe()`` prints the table
(name, JSBSim property, unit, bounds, meaning).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class StateVar:
    """One state variable: its name in observations and datasets, and where JSBSim keeps it.

    ``low``/``high`` bound the variable physically (they become the observation space); they
    are not limits the task enforces.
    """

    name: str
    prop: str
    unit: str
    low: float
    high: float
    description: str


CATALOGUE: tuple[StateVar, ...] = (
    StateVar("lat_deg", "position/lat-geod-deg", "deg", -90.0, 90.0, "geodetic latitude"),
    StateVar("lon_deg", "position/long-gc-deg", "deg", -180.0, 180.0, "longitude"),
    StateVar("altitude_ft", "position/h-sl-ft", "ft", -2000.0, 1e5, "altitude above sea level"),
    StateVar("altitude_agl_ft", "position/h-agl-ft", "ft", -2000.0, 1e5, "height above ground"),
    StateVar("roll_deg", "attitude/phi-deg", "deg", -180.0, 180.0, "roll (bank) angle"),
    StateVar("pitch_deg", "attitude/theta-deg", "deg", -90.0, 90.0, "pitch angle"),
    StateVar("heading_deg", "attitude/psi-deg", "deg", 0.0, 360.0, "true heading"),
    StateVar("airspeed_kts", "velocities/vc-kts", "kt", 0.0, 2000.0, "calibrated airspeed"),
    StateVar("true_airspeed_kts", "velocities/vtrue-kts", "kt", 0.0, 3000.0, "true airspeed"),
    StateVar("vertical_speed_fps", "velocities/h-dot-fps", "ft/s", -3000.0, 3000.0, "climb rate"),
    StateVar("u_fps", "velocities/u-fps", "ft/s", -5000.0, 5000.0, "body-axis forward velocity"),
    StateVar("v_fps", "velocities/v-fps", "ft/s", -5000.0, 5000.0, "body-axis side velocity"),
    StateVar("w_fps", "velocities/w-fps", "ft/s", -5000.0, 5000.0, "body-axis down velocity"),
    StateVar("p_rad_s", "velocities/p-rad_sec", "rad/s", -20.0, 20.0, "roll rate"),
    StateVar("q_rad_s", "velocities/q-rad_sec", "rad/s", -20.0, 20.0, "pitch rate"),
    StateVar("r_rad_s", "velocities/r-rad_sec", "rad/s", -20.0, 20.0, "yaw rate"),
    StateVar("alpha_deg", "aero/alpha-deg", "deg", -180.0, 180.0, "angle of attack"),
    StateVar("beta_deg", "aero/beta-deg", "deg", -180.0, 180.0, "sideslip angle"),
    StateVar("mach", "velocities/mach", "1", 0.0, 5.0, "Mach number"),
    StateVar(
        "load_factor_g",
        "accelerations/n-pilot-z-norm",
        "g",
        -20.0,
        20.0,
        "normal load factor at the pilot (positive down)",
    ),
    StateVar("aileron_cmd", "fcs/aileron-cmd-norm", "1", -1.0, 1.0, "aileron command"),
    StateVar("elevator_cmd", "fcs/elevator-cmd-norm", "1", -1.0, 1.0, "elevator command"),
    StateVar("rudder_cmd", "fcs/rudder-cmd-norm", "1", -1.0, 1.0, "rudder command"),
    StateVar("throttle_cmd", "fcs/throttle-cmd-norm", "1", 0.0, 1.0, "throttle command (engine 1)"),
    StateVar("thrust_lbs", "propulsion/engine/thrust-lbs", "lbf", -1e5, 1e6, "thrust (engine 1)"),
    StateVar("sim_time_s", "simulation/sim-time-sec", "s", 0.0, 1e7, "simulation time"),
)

NAMES: tuple[str, ...] = tuple(v.name for v in CATALOGUE)
INDEX: dict[str, int] = {v.name: i for i, v in enumerate(CATALOGUE)}
BY_NAME: dict[str, StateVar] = {v.name: v for v in CATALOGUE}
LOW = np.array([v.low for v in CATALOGUE])
HIGH = np.array([v.high for v in CATALOGUE])

# The contract's action: [aileron, elevator, rudder, throttle].
ACTION_NAMES: tuple[str, ...] = ("aileron", "elevator", "rudder", "throttle")
ACTION_LOW = np.array([-1.0, -1.0, -1.0, 0.0], dtype=np.float32)
ACTION_HIGH = np.array([1.0, 1.0, 1.0, 1.0], dtype=np.float32)

# What an aircraft sees of an opponent by default: position and orientation (the paper).
POSITION = ("lat_deg", "lon_deg", "altitude_ft")
ORIENTATION = ("roll_deg", "pitch_deg", "heading_deg")
DEFAULT_OPPONENT_VIEW: tuple[str, ...] = POSITION + ORIENTATION


def task_columns(observation_names: Sequence[str]) -> list[int]:
    """Where a task's own columns (targets, errors, integrals, gates: every name that is not
    a catalogue state variable) sit in its observation; a dataset's environment state."""
    return [i for i, name in enumerate(observation_names) if name not in BY_NAME]


def indices(names: tuple[str, ...] | list[str]) -> np.ndarray:
    """Catalogue indices of ``names``; an unknown name is a clear error listing the known ones."""
    from gymfg_il.errors import ConfigError

    unknown = [n for n in names if n not in INDEX]
    if unknown:
        raise ConfigError(
            f"unknown state variable(s) {unknown}: choose from gymfg_il.sim.properties.NAMES "
            f"({', '.join(NAMES)})"
        )
    return np.array([INDEX[n] for n in names], dtype=np.intp)


def describe() -> str:
    """The catalogue as a Markdown table."""
    rows = [
        f"| {v.name} | `{v.prop}` | {v.unit} | [{v.low:g}, {v.high:g}] | {v.description} |"
        for v in CATALOGUE
    ]
    head = "| name | JSBSim property | unit | bounds | meaning |\n| --- | --- | --- | --- | --- |"
    return "\n".join([head, *rows])


class StateView:
    """Read a state vector by name: ``view.altitude_ft`` or ``view["altitude_ft"]``.

    Views wrap a catalogue-ordered vector (or a subset with its own names, for opponent views)
    without copying, so rewards can be one lambda comparing aspects of states.
    """

    __slots__ = ("_index", "values")

    def __init__(self, values: np.ndarray, names: tuple[str, ...] = NAMES) -> None:
        self.values = values
        self._index = INDEX if names is NAMES else {n: i for i, n in enumerate(names)}

    def __getattr__(self, name: str) -> float:
        try:
            return float(self.values[self._index[name]])
        except KeyError:
            raise AttributeError(
                f"state has no variable {name!r}; it has {', '.join(self._index)}"
            ) from None

    def __getitem__(self, name: str) -> float:
        return self.__getattr__(name)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def names(self) -> tuple[str, ...]:
        return tuple(self._index)

    def rename(self, names: tuple[str, ...]) -> None:
        """Hold a vector of other variables from now on (NaN until filled): an online
        client learns the opponent view from the server only when it joins."""
        self._index = {n: i for i, n in enumerate(names)}
        self.values = np.full(len(names), np.nan)

    def as_dict(self) -> dict[str, float]:
        return {n: float(self.values[i]) for n, i in self._index.items()}

    def __repr__(self) -> str:
        body = ", ".join(f"{k}={v:.4g}" for k, v in self.as_dict().items())
        return f"StateView({body})"
