"""Initial conditions, written as a JSBSim v2 initialization file on every reset.

Setting ``ic/*`` properties one by one leaves round-off that depends on the previous episode
(each setter recomputes from the last position and velocity), so a reused ``FGFDMExec`` would not
repeat a trajectory bit for bit. A v2 file with an ECEF position, a local orientation and a local
velocity overwrites the whole initial state at once, which makes a reused instance identical to a
fresh one (``tests/sim/test_simulation.py`` checks it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gymfg_il.errors import ConfigError
from gymfg_il.units import KT_TO_FPS

# WGS84 in feet, as JSBSim's default planet.
_A_FT = 20925646.32546
_B_FT = 20855486.5951
_E2 = 1.0 - (_B_FT * _B_FT) / (_A_FT * _A_FT)


def ecef_ft(latitude_deg: float, longitude_deg: float, altitude_ft: float) -> tuple[float, ...]:
    """Earth-centred, earth-fixed position (ft) of a geodetic point on the WGS84 ellipsoid."""
    lat = math.radians(latitude_deg)
    lon = math.radians(longitude_deg)
    n = _A_FT / math.sqrt(1.0 - _E2 * math.sin(lat) ** 2)
    return (
        (n + altitude_ft) * math.cos(lat) * math.cos(lon),
        (n + altitude_ft) * math.cos(lat) * math.sin(lon),
        (n * (1.0 - _E2) + altitude_ft) * math.sin(lat),
    )


@dataclass(frozen=True, slots=True)
class InitialConditions:
    """An aircraft's state at the start of an episode: trimmed straight, level flight by
    default (the pitch and the controls that hold it, found by JSBSim's trim; see
    ``gymfg_il.sim.trim``), or an untrimmed start with a given attitude.

    Attributes:
        latitude_deg: geodetic latitude.
        longitude_deg: longitude.
        altitude_ft: geodetic altitude above sea level.
        heading_deg: true heading (0 = north).
        airspeed_kts: true airspeed, along a horizontal flight path.
        roll_deg: initial bank angle.
        pitch_deg: initial pitch angle.
        terrain_elevation_ft: ground elevation under the aircraft.
        trimmed: start in trimmed straight, level flight (pitch, pitch/roll/yaw trim and
            throttle from JSBSim's trim at this altitude and airspeed; the default). A state
            JSBSim cannot trim is a ``ConfigError`` naming it. ``False`` starts with the given
            roll and pitch, zero trims and the caller's throttle: an untrimmed or unusual
            start (upset recovery, say), which opens with a 1-2 s transient.
    """

    latitude_deg: float = 37.6189
    longitude_deg: float = -122.375
    altitude_ft: float = 5000.0
    heading_deg: float = 0.0
    airspeed_kts: float = 110.0
    roll_deg: float = 0.0
    pitch_deg: float = 0.0
    terrain_elevation_ft: float = 0.0
    trimmed: bool = True

    def __post_init__(self) -> None:
        problems = []
        if not isinstance(self.trimmed, bool):
            problems.append(f"trimmed={self.trimmed!r} must be True or False")
        for name in self.__dataclass_fields__:
            if name == "trimmed":
                continue
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                problems.append(f"{name}={value!r} must be a finite number")
        if problems:
            raise ConfigError("InitialConditions: " + "; ".join(problems))
        if not -90.0 <= self.latitude_deg <= 90.0:
            problems.append(f"latitude_deg={self.latitude_deg} must lie in [-90, 90]")
        if self.airspeed_kts < 0:
            problems.append(f"airspeed_kts={self.airspeed_kts} must not be negative")
        if self.altitude_ft <= self.terrain_elevation_ft:
            problems.append(
                f"altitude_ft={self.altitude_ft} must be above terrain_elevation_ft="
                f"{self.terrain_elevation_ft}"
            )
        if self.trimmed and (self.roll_deg or self.pitch_deg):
            problems.append(
                f"roll_deg={self.roll_deg}, pitch_deg={self.pitch_deg}: a trimmed start is "
                "straight and level (its pitch comes from the trim); give trimmed=False to "
                "start banked or pitched"
            )
        if problems:
            raise ConfigError("InitialConditions: " + "; ".join(problems))

    def to_xml(self, wind_fps: tuple[float, float] = (0.0, 0.0)) -> str:
        """A JSBSim v2 initialization file holding exactly this state; with a wind (north,
        east, ft/s) the ground velocity is the air velocity plus the wind, so the airspeed
        is the one asked for."""
        x, y, z = ecef_ft(self.latitude_deg, self.longitude_deg, self.altitude_ft)
        speed = self.airspeed_kts * KT_TO_FPS
        psi = math.radians(self.heading_deg)
        north, east = speed * math.cos(psi), speed * math.sin(psi)
        if wind_fps != (0.0, 0.0):
            north, east = north + wind_fps[0], east + wind_fps[1]
        return (
            '<?xml version="1.0"?>\n<initialize name="gymfg" version="2.0">\n'
            f' <elevation unit="FT">{self.terrain_elevation_ft!r}</elevation>\n'
            f' <position frame="ECEF"><x unit="FT">{x!r}</x><y unit="FT">{y!r}</y>'
            f'<z unit="FT">{z!r}</z></position>\n'
            f' <orientation unit="DEG" frame="LOCAL"><roll>{self.roll_deg!r}</roll>'
            f"<pitch>{self.pitch_deg!r}</pitch><yaw>{self.heading_deg!r}</yaw></orientation>\n"
            f' <velocity unit="FT/SEC" frame="LOCAL"><x>{north!r}</x><y>{east!r}</y>'
            "<z>0.0</z></velocity>\n</initialize>\n"
        )
