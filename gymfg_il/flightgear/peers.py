"""FlightGear aircraft heard over multiplayer: the position messages other FlightGear
instances (or a multiplayer server relaying several) send, decoded, and the latest of each
kept per callsign.

``decode`` reads one message (protocol 1.1, id 7; see ``multiplayer`` for the layout):
callsign, model, FlightGear's time, the ECEF position turned back into latitude, longitude
and altitude, the ECEF angle-axis orientation turned back into roll, pitch and heading, and
the body-frame velocities. FlightGear 2020.3 sends 893 bytes: the 232 we send ourselves plus
a version-2 property section (control-surface positions among them), which is skipped.

``MultiplayerLink`` is one UDP socket on a configured port: polled without blocking, it keeps
the latest ``Peer`` per callsign and forgets one that has been silent for ``timeout_s``; it
also sends our aircraft from that same socket, so a multiplayer server (which answers to a
packet's source address) relays the others back to it.
"""

from __future__ import annotations

import logging
import math
import socket
import struct
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.multiplayer import (
    FG_D2R,
    HEADER,
    MAGIC,
    POSITION_MESSAGE,
    WGS84_A,
    WGS84_E2,
    Quat,
    _local_frame,
    _mul,
    pack,
    port_problem,
)
from gymfg_il.names import name_problem
from gymfg_il.sim.properties import BY_NAME, DEFAULT_OPPONENT_VIEW
from gymfg_il.units import FT_TO_M, RAD_TO_DEG, wrap_360

log = logging.getLogger(__name__)

# what a position message holds before its rate vectors' padding: model, time, lag, position,
# orientation, linear velocity (the rest of FlightGear's body is not needed)
_BODY_HEAD = struct.Struct(">96s2d3d3f3f")
_MIN_SIZE = HEADER.size + _BODY_HEAD.size

_FG_R2D = 1.0 / FG_D2R


class MessageError(ValueError):
    """A datagram that is not a FlightGear position message."""


@dataclass(frozen=True)
class Peer:
    """One aircraft as its last position message describes it.

    Attributes:
        callsign: as FlightGear keeps it (7 characters at most).
        model: the FlightGear model path (``Aircraft/c172p/Models/c172p.xml``).
        time_s: the sender's own clock at the message.
        lat_deg, lon_deg, altitude_ft: WGS84 geodetic position.
        roll_deg, pitch_deg, heading_deg: attitude (heading true, 0..360).
        velocity_mps: body-frame velocity (forward, right, down), m/s.
        heard_at: our monotonic clock when it arrived.
    """

    callsign: str
    model: str
    time_s: float
    lat_deg: float
    lon_deg: float
    altitude_ft: float
    roll_deg: float
    pitch_deg: float
    heading_deg: float
    velocity_mps: tuple[float, float, float]
    heard_at: float = 0.0

    @property
    def pose(self) -> tuple[float, float, float, float, float, float]:
        """lat_deg, lon_deg, altitude_ft, roll_deg, pitch_deg, heading_deg: the opponent view."""
        return (
            self.lat_deg,
            self.lon_deg,
            self.altitude_ft,
            self.roll_deg,
            self.pitch_deg,
            self.heading_deg,
        )

    def summary(self) -> dict[str, object]:
        """What the ``listen`` diagnostic prints."""
        return {
            "callsign": self.callsign,
            "model": self.model,
            "latitude_deg": round(self.lat_deg, 7),
            "longitude_deg": round(self.lon_deg, 7),
            "altitude_ft": round(self.altitude_ft, 2),
            "roll_deg": round(self.roll_deg, 3),
            "pitch_deg": round(self.pitch_deg, 3),
            "heading_deg": round(self.heading_deg, 3),
        }


def geodetic(x: float, y: float, z: float) -> tuple[float, float, float]:
    """WGS84 latitude, longitude (degrees) and altitude (ft) of an ECEF position (m), with
    FlightGear's degree constant (``multiplayer.FG_D2R``).

    Defined everywhere, the polar axis and the Earth's centre included: the latitude iterates
    ``tan(lat) = (z + e2 N sin(lat)) / p`` and the altitude is ``p cos(lat) + z sin(lat) -
    a sqrt(1 - e2 sin(lat)^2)``, neither of which divides (on the axis, ``p = 0``, the
    latitude is exactly +-90 and the altitude ``|z| - b``). The latitude's error shrinks by
    ~e2 (1/150) an iteration; six leave well under a micrometre above the Earth's surface.
    """
    lon = math.atan2(y, x)
    p = math.hypot(x, y)
    lat = math.atan2(z, p * (1.0 - WGS84_E2))
    for _ in range(6):
        s = math.sin(lat)
        lat = math.atan2(z + WGS84_E2 * WGS84_A / math.sqrt(1.0 - WGS84_E2 * s * s) * s, p)
    s = math.sin(lat)
    h = p * math.cos(lat) + z * s - WGS84_A * math.sqrt(1.0 - WGS84_E2 * s * s)
    # FlightGear's degree is a float32 a little short of pi/180: keep the poles and the date
    # line where they are
    lat_deg = max(-90.0, min(90.0, lat * _FG_R2D))
    lon_deg = max(-180.0, min(180.0, lon * _FG_R2D))
    return lat_deg, lon_deg, h / FT_TO_M


def attitude(
    angle_axis: Sequence[float], lat_deg: float, lon_deg: float
) -> tuple[float, float, float]:
    """Roll, pitch and heading (degrees; heading 0..360) of an ECEF angle-axis orientation."""
    ax, ay, az = angle_axis
    angle = math.sqrt(ax * ax + ay * ay + az * az)
    if angle > 1e-12:
        s = math.sin(0.5 * angle) / angle
        q: Quat = (math.cos(0.5 * angle), ax * s, ay * s, az * s)
    else:
        q = (1.0, 0.0, 0.0, 0.0)
    w, x, y, z = _local_frame(math.radians(lat_deg), math.radians(lon_deg))
    w, x, y, z = _mul((w, -x, -y, -z), q)
    roll = math.atan2(2 * (y * z + w * x), w * w - x * x - y * y + z * z)
    pitch = -math.asin(max(-1.0, min(1.0, 2 * (x * z - w * y))))
    heading = math.atan2(2 * (x * y + w * z), w * w + x * x - y * y - z * z)
    return roll * RAD_TO_DEG, pitch * RAD_TO_DEG, wrap_360(heading * RAD_TO_DEG)


def decode(data: bytes, heard_at: float = 0.0) -> Peer:
    """One position message as a ``Peer``; anything else raises ``MessageError``: a datagram
    too short, of another kind or with non-finite numbers, a callsign that is not a printable
    name (``names.name_problem``) or a model path that is not printable, and a pose outside
    the bounds our own aircraft's state declares (``sim.properties``: e.g. an altitude of
    -2000..100000 ft), so that an opponent row or a reward aimed at a FlightGear aircraft
    sees only what an aircraft can be."""
    if len(data) < _MIN_SIZE:
        raise MessageError(f"{len(data)} bytes: shorter than a position message")
    magic, _version, kind, length, _range, _reply, raw_callsign = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise MessageError(f"magic {magic:#x} is not FlightGear's {MAGIC:#x}")
    if kind != POSITION_MESSAGE:
        raise MessageError(f"message id {kind} is not a position message ({POSITION_MESSAGE})")
    if length > len(data):
        raise MessageError(f"message says {length} bytes, {len(data)} arrived")
    model, time_s, _lag, x, y, z, ox, oy, oz, vx, vy, vz = _BODY_HEAD.unpack_from(data, HEADER.size)
    if not all(math.isfinite(v) for v in (time_s, x, y, z, ox, oy, oz, vx, vy, vz)):
        raise MessageError("a position message with a non-finite position, angle or velocity")
    callsign, model_path = _text(raw_callsign), _text(model)
    problem = name_problem(callsign, "callsign")
    if problem:
        raise MessageError(problem)
    if not model_path.isprintable():  # a path, up to 95 characters: longer than a name
        raise MessageError(f"model {model_path!r} holds characters that are not printable")
    lat, lon, alt = geodetic(x, y, z)
    roll, pitch, heading = attitude((ox, oy, oz), lat, lon)
    for name, value in zip(
        DEFAULT_OPPONENT_VIEW, (lat, lon, alt, roll, pitch, heading), strict=True
    ):
        var = BY_NAME[name]
        if not var.low <= value <= var.high:  # NaN too
            raise MessageError(
                f"{name}={value:g} {var.unit} from ECEF ({x:g}, {y:g}, {z:g}) m is outside "
                f"{var.low:g}..{var.high:g}: not where an aircraft flies"
            )
    return Peer(
        callsign=callsign,
        model=model_path,
        time_s=time_s,
        lat_deg=lat,
        lon_deg=lon,
        altitude_ft=alt,
        roll_deg=roll,
        pitch_deg=pitch,
        heading_deg=heading,
        velocity_mps=(vx, vy, vz),
        heard_at=heard_at,
    )


def _text(raw: bytes) -> str:
    return raw.split(b"\0", 1)[0].decode("ascii", "replace")


Address = tuple[str, int]


@dataclass(frozen=True)
class MultiplayerConfig:
    """FlightGear multiplayer for an environment: who listens where, and where we send.

    Attributes:
        listen_port: UDP port we receive position messages on: a FlightGear's
            ``--multiplay=out,HZ,HOST,PORT`` (or a server's reply port). At most 32767.
        host: address the socket binds to; loopback by default, so nothing beyond this
            machine reaches it unless you say so (``0.0.0.0`` for every interface).
        send_to: ``(host, port)`` addresses our aircraft are sent to as multiplayer
            traffic: a FlightGear's ``--multiplay=in`` port, or a multiplayer server.
        timeout_s: a FlightGear aircraft silent this long is dropped (absent).
        team: the team name FlightGear aircraft fly for (every one is an opponent).
    """

    listen_port: int = 5002
    host: str = "127.0.0.1"
    send_to: tuple[Address, ...] = ()
    timeout_s: float = 3.0
    team: str = "flightgear"

    def __post_init__(self) -> None:
        problems = []
        problem = port_problem(self.listen_port)
        if problem:
            problems.append(f"listen_port: {problem}")
        bad = [a for a in self.send_to if not (isinstance(a, (tuple, list)) and len(a) == 2)]
        if bad:
            raise ConfigError(
                f"multiplayer: send_to entries must be (host, port) pairs, got {bad!r}; "
                'e.g. send_to=[("127.0.0.1", 5000)]'
            )
        send_to = tuple((str(h), p) for h, p in self.send_to)
        object.__setattr__(self, "send_to", send_to)
        problems += [f"send_to {h}: {p}" for h, port in send_to if (p := port_problem(port))]
        if not (isinstance(self.timeout_s, (int, float)) and self.timeout_s > 0):
            problems.append(f"timeout_s={self.timeout_s!r} must be a positive number of seconds")
        if problems:
            raise ConfigError("multiplayer: " + "; ".join(problems))


class MultiplayerLink:
    """One UDP socket: receives FlightGear position messages, sends ours.

    ``poll()`` drains what arrived without blocking and returns the aircraft heard within
    ``timeout_s`` (by callsign); call it once per step. ``clock`` is injectable for tests.
    Nothing that arrives raises out of ``poll``: a datagram that fails to decode, for any
    reason, is dropped and counted in ``rejected``.
    """

    def __init__(
        self, config: MultiplayerConfig, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.config = config
        self.clock = clock
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind((config.host, config.listen_port))
        except OSError as err:
            self.sock.close()
            raise ConfigError(
                f"multiplayer: cannot listen on {config.host}:{config.listen_port} ({err}); "
                "pick a free port (a FlightGear on this machine needs its own --multiplay=in "
                "port, different from this one)"
            ) from err
        self.sock.setblocking(False)
        self.peers: dict[str, Peer] = {}
        self.received = self.rejected = self.sent = 0
        self.broken = 0  # rejected ones that raised something else than MessageError
        log.info(
            "multiplayer: listening on %s:%d, sending to %s",
            config.host,
            config.listen_port,
            list(config.send_to) or "nobody",
        )

    def poll(self) -> dict[str, Peer]:
        now = self.clock()
        while True:
            try:
                data = self.sock.recv(4096)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:  # e.g. an ICMP "port unreachable" from an earlier send
                continue
            try:
                peer = decode(data, now)
            except MessageError as err:
                self._reject(err)
                continue
            except Exception as err:  # a decoding bug: the datagram goes, the run goes on
                if not self.broken:
                    log.warning("multiplayer: a datagram broke the decoder (%r): rejected", err)
                self.broken += 1
                self._reject(err)
                continue
            self.received += 1
            self.peers[peer.callsign] = peer
        stale = [c for c, p in self.peers.items() if now - p.heard_at > self.config.timeout_s]
        for callsign in stale:
            log.info("multiplayer: %s silent for %.1f s, dropped", callsign, self.config.timeout_s)
            del self.peers[callsign]
        return self.peers

    def _reject(self, err: Exception) -> None:
        self.rejected += 1
        log.debug("multiplayer: datagram %d rejected: %s", self.rejected, err)

    def send(self, callsign: str, model: str, pose: Sequence[float]) -> None:
        """Send one of our aircraft (``pose`` as in ``Peer.pose``) to every ``send_to``."""
        if not self.config.send_to:
            return
        packet = pack(callsign, model, time.monotonic(), *pose)
        for address in self.config.send_to:
            try:
                self.sock.sendto(packet, address)
            except OSError as err:  # nobody there yet is fine; a bad address is logged once
                if self.sent == 0:
                    log.warning("multiplayer: sending to %s failed: %s", address, err)
        self.sent += 1

    def close(self) -> None:
        self.sock.close()


__all__ = [
    "MessageError",
    "MultiplayerConfig",
    "MultiplayerLink",
    "Peer",
    "attitude",
    "decode",
    "geodetic",
]
