"""Trimmed starts: the pitch and the controls that hold straight, level flight.

JSBSim's own trim routine (``simulation/do_simple_trim``, full mode) finds them for an
aircraft at an altitude and airspeed. It costs ~4 ms, a reset ~0.1 ms, so it does not run on
every reset: each aircraft model is trimmed on a grid (every 1,000 ft of altitude, every
10 kt of airspeed, at a fixed place and heading, in calm air) in an instance of its own, and a
start between grid points interpolates its four corners. Results are cached per process;
the trimming instance is reset from an initial-conditions file before every trim, so a grid
point comes out the same whichever points were trimmed before it, in any process, and resets
stay bit-reproducible. A trimmed start puts the trim in the controls (``Simulation.reset``:
its ``start_action``), never in JSBSim's trim commands, so an action is the whole command and
the trim's controls with its throttle are hands-off flight.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions

ALTITUDE_STEP_FT = 1000.0
AIRSPEED_STEP_KTS = 10.0


@dataclass(frozen=True, slots=True)
class Trim:
    """Straight, level flight of one aircraft at one altitude and airspeed.

    Attributes:
        pitch_deg: pitch angle (= angle of attack on a level path).
        elevator: the elevator command that holds it (JSBSim's trim finds it as
            ``fcs/pitch-trim-cmd-norm``).
        aileron, rudder: the aileron and rudder commands that hold it.
        throttle: throttle command of every engine.
    """

    pitch_deg: float
    elevator: float
    aileron: float
    rudder: float
    throttle: float

    def blend(self, other: Trim, w: float) -> Trim:
        """``self`` * (1 - w) + ``other`` * w, field by field."""
        return Trim(*(a + (b - a) * w for a, b in zip(self.values(), other.values(), strict=True)))

    def values(self) -> tuple[float, float, float, float, float]:
        return (self.pitch_deg, self.elevator, self.aileron, self.rudder, self.throttle)


class Trimmer(Protocol):
    """What trims: a JSBSim instance that resets to an untrimmed start (``Simulation``, which
    passes itself as the maker: a reset needs a trim, and a trim a reset)."""

    fdm: Any

    def reset(self, ic: InitialConditions, throttle: float) -> Any: ...


Maker = Callable[[str, int], Trimmer]  # (model, sim_hz) -> a new instance to trim in

# a point JSBSim could not trim is remembered as its error: near the envelope's edge every
# reset would otherwise try it again (~4 ms and a JSBSim message each time)
_GRID: dict[tuple[str, int, float, float], Trim | ConfigError] = {}
_TRIMMERS: dict[tuple[str, int], Trimmer] = {}


def _trim_point(
    model: str, sim_hz: int, altitude_ft: float, airspeed_kts: float, make: Maker
) -> Trim:
    """JSBSim's full trim at one grid point, in this process's trimming instance."""
    import jsbsim

    sim = _TRIMMERS.get((model, sim_hz))
    if sim is None:
        sim = _TRIMMERS[(model, sim_hz)] = make(model, sim_hz)
    ic = InitialConditions(altitude_ft=altitude_ft, airspeed_kts=airspeed_kts, trimmed=False)
    sim.reset(ic, throttle=0.5)
    fdm = sim.fdm
    try:
        fdm["simulation/do_simple_trim"] = 1
    except jsbsim.TrimFailureError:
        raise ConfigError(
            f"JSBSim cannot trim {model} for straight, level flight at {altitude_ft:g} ft and "
            f"{airspeed_kts:g} kt (true airspeed); start it nearer its cruise altitude and "
            "speed, or give InitialConditions(trimmed=False) for an untrimmed start"
        ) from None
    return Trim(
        fdm["attitude/theta-deg"],
        fdm["fcs/pitch-trim-cmd-norm"],
        fdm["fcs/aileron-cmd-norm"],
        fdm["fcs/rudder-cmd-norm"],
        fdm["fcs/throttle-cmd-norm[0]"],
    )


def _grid(model: str, sim_hz: int, altitude_ft: float, airspeed_kts: float, make: Maker) -> Trim:
    key = (model, sim_hz, altitude_ft, airspeed_kts)
    found = _GRID.get(key)
    if found is None:
        try:
            found = _trim_point(model, sim_hz, altitude_ft, airspeed_kts, make)
        except ConfigError as err:
            found = err
        _GRID[key] = found
    if isinstance(found, ConfigError):
        raise ConfigError(str(found)) from None  # a new one: no traceback piling up
    return found


def trim_for(model: str, altitude_ft: float, airspeed_kts: float, sim_hz: int, make: Maker) -> Trim:
    """The trim of JSBSim ``model`` at ``altitude_ft`` and ``airspeed_kts`` (true airspeed),
    interpolated between the grid points around it (trimmed on first use). Near the edge of
    the aircraft's envelope, where a grid point around it cannot be trimmed, the point
    itself is trimmed instead."""
    a, s = altitude_ft / ALTITUDE_STEP_FT, airspeed_kts / AIRSPEED_STEP_KTS
    i, j = math.floor(a), math.floor(s)
    wa, ws = a - i, s - j
    try:
        corners = [
            _grid(model, sim_hz, ii * ALTITUDE_STEP_FT, jj * AIRSPEED_STEP_KTS, make)
            for ii in (i, i + 1)
            for jj in (j, j + 1)
        ]
    except ConfigError:
        return _grid(model, sim_hz, altitude_ft, airspeed_kts, make)
    low = corners[0].blend(corners[1], ws)
    high = corners[2].blend(corners[3], ws)
    return low.blend(high, wa)
