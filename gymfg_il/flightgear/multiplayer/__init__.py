"""Other aircraft in a FlightGear view: FlightGear's multiplayer position message.

A view follows one aircraft through the native-fdm stream (``netfdm``). The simulation's
other aircraft reach it as multiplayer traffic: one position message per aircraft and step,
sent over UDP to the port the view listens on (``fgfs --multiplay=in,HZ,127.0.0.1,PORT``,
which ``FlightGear(multiplayer_port=...)`` adds). FlightGear then lists each of them under
``/ai/models/multiplayer[i]`` and draws its model.

Only position and orientation are sent: exactly what an opponent may see of another team
(``DEFAULT_OPPONENT_VIEW``), so an online client can show its opponents too.

Message (XDR, big-endian), protocol 1.1: a 32-byte header (magic ``FGFS``, version, message id
7, length, requested range, reply port, callsign[8]) and a 200-byte body (model path[96], time
and lag as doubles, ECEF position in metres as doubles, orientation as an ECEF angle-axis
vector and four zero rate vectors as floats, padding).
"""

from __future__ import annotations

import contextlib
import math
import socket
import struct
import time
from collections.abc import Sequence

from gymfg_il.errors import ConfigError
from gymfg_il.units import DEG_TO_RAD, FT_TO_M

MAGIC = 0x46474653  # "FGFS"
PROTOCOL = 0x00010001
POSITION_MESSAGE = 7
CALLSIGN_BYTES = 8  # FlightGear keeps 7 characters and a terminating zero
HEADER = struct.Struct(">6I8s")
BODY = struct.Struct(">96s2d3d3f12fI")
SIZE = HEADER.size + BODY.size
assert SIZE == 232, SIZE
# FlightGear 2020.3 keeps its multiplayer ports in a signed 16-bit property
MAX_PORT = 32767


def port_problem(port: object) -> str | None:
    """Why FlightGear cannot listen for traffic on ``port``, or None when it can."""
    if isinstance(port, int) and not isinstance(port, bool) and 0 < port <= MAX_PORT:
        return None
    return (
        f"multiplayer port {port!r}: FlightGear 2020.3 keeps multiplayer ports in a signed "
        f"16-bit property; pick one in 1..{MAX_PORT}"
    )


# FlightGear models for JSBSim models without a FlightGear aircraft of their own: the AI
# models that ship with FlightGear's base data
MODELS = {
    "c172p": "Aircraft/c172p/Models/c172p.xml",
    "f15": "AI/Aircraft/F-15/Models/F-15.xml",
    "A320": "AI/Aircraft/A320/A320-Lufthansa.xml",
}
_FALLBACK = "Aircraft/ufo/Models/ufo.xml"

WGS84_A = 6378137.0  # semi-major axis, m
WGS84_E2 = (1 / 298.257223563) * (2 - 1 / 298.257223563)  # first eccentricity squared
# FlightGear turns degrees into radians for its multiplayer position with a float32 constant
# (SimGear's SG_DEGREES_TO_RADIANS), 7.7e-9 short of pi/180: a 9 cm shift at San Francisco.
# Positions use its constant both ways, so what FlightGear sends decodes to what it shows.
FG_D2R: float = struct.unpack("f", struct.pack("f", DEG_TO_RAD))[0]


def ecef(lat_deg: float, lon_deg: float, altitude_ft: float) -> tuple[float, float, float]:
    """Earth-centred, earth-fixed position (m) of a WGS84 geodetic position, as FlightGear
    computes it (``FG_D2R``)."""
    lat, lon, h = lat_deg * FG_D2R, lon_deg * FG_D2R, altitude_ft * FT_TO_M
    s = math.sin(lat)
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * s * s)
    c = (n + h) * math.cos(lat)
    return c * math.cos(lon), c * math.sin(lon), (n * (1.0 - WGS84_E2) + h) * s


Quat = tuple[float, float, float, float]  # w, x, y, z


def _mul(a: Quat, b: Quat) -> Quat:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def _local_frame(lat: float, lon: float) -> Quat:
    """Rotation from ECEF to the local north-east-down frame (SimGear's fromLonLatRad)."""
    z, y = 0.5 * lon, -0.25 * math.pi - 0.5 * lat
    return (
        math.cos(z) * math.cos(y),
        -math.sin(z) * math.sin(y),
        math.cos(z) * math.sin(y),
        math.sin(z) * math.cos(y),
    )


def _euler(yaw: float, pitch: float, roll: float) -> Quat:
    sz, cz = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    sy, cy = math.sin(0.5 * pitch), math.cos(0.5 * pitch)
    sx, cx = math.sin(0.5 * roll), math.cos(0.5 * roll)
    return (
        cx * cy * cz + sx * sy * sz,
        sx * cy * cz - cx * sy * sz,
        cx * sy * cz + sx * cy * sz,
        cx * cy * sz - sx * sy * cz,
    )


def orientation(
    lat_deg: float, lon_deg: float, roll_deg: float, pitch_deg: float, heading_deg: float
) -> tuple[float, float, float]:
    """The body attitude in the ECEF frame as an angle-axis vector (radians)."""
    q = _mul(
        _local_frame(lat_deg * DEG_TO_RAD, lon_deg * DEG_TO_RAD),
        _euler(heading_deg * DEG_TO_RAD, pitch_deg * DEG_TO_RAD, roll_deg * DEG_TO_RAD),
    )
    w, x, y, z = q
    if w < 0:  # the shorter of the two equivalent rotations
        w, x, y, z = -w, -x, -y, -z
    half = math.acos(min(1.0, w))
    s = math.sin(half)
    if s < 1e-12:
        return 0.0, 0.0, 0.0
    k = 2.0 * half / s
    return x * k, y * k, z * k


def model_path(model: str) -> str:
    """The FlightGear model drawn for a JSBSim aircraft model (a UFO when none ships)."""
    return MODELS.get(model, _FALLBACK)


def pack(
    callsign: str,
    model: str,
    time_s: float,
    lat_deg: float,
    lon_deg: float,
    altitude_ft: float,
    roll_deg: float,
    pitch_deg: float,
    heading_deg: float,
) -> bytes:
    """One position message: ``callsign`` (7 characters are kept) flying JSBSim ``model``."""
    body = BODY.pack(
        model_path(model).encode("ascii"),
        time_s,
        0.1,  # lag: how far FlightGear may extrapolate
        *ecef(lat_deg, lon_deg, altitude_ft),
        *orientation(lat_deg, lon_deg, roll_deg, pitch_deg, heading_deg),
        *([0.0] * 12),
        0,
    )
    header = HEADER.pack(
        MAGIC,
        PROTOCOL,
        POSITION_MESSAGE,
        SIZE,
        100,  # requested range, nm
        0,
        callsign.encode("ascii", "replace")[: CALLSIGN_BYTES - 1],
    )
    return header + body


class TrafficSender:
    """Sends aircraft as multiplayer traffic to the multiplayer ports of some views."""

    def __init__(self, ports: Sequence[int], host: str = "127.0.0.1") -> None:
        problems = [p for p in map(port_problem, ports) if p]
        if problems:
            raise ConfigError("; ".join(problems))
        self.targets = [(host, int(port)) for port in ports]
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sent = 0

    def send(self, callsign: str, model: str, pose: Sequence[float]) -> None:
        """``pose``: lat_deg, lon_deg, altitude_ft, roll_deg, pitch_deg, heading_deg."""
        packet = pack(callsign, model, time.monotonic(), *pose)
        for target in self.targets:
            with contextlib.suppress(OSError):  # a view may come later
                self.sock.sendto(packet, target)
        self.sent += 1

    def close(self) -> None:
        self.sock.close()
