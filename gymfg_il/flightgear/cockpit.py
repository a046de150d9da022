"""FlightGear as the cockpit: the pilot's controls, read from FlightGear's native-ctrls stream.

A person flies one of our JSBSim aircraft from FlightGear itself, with FlightGear's own
joystick and keyboard bindings: FlightGear shows our state (``--fdm=null`` and
``--native-fdm=socket,in,...``, fed by the env's views) and sends what the pilot commands::

    fgfs --fdm=null --native-fdm=socket,in,30,,5600,udp \\
         --native-ctrls=socket,out,30,127.0.0.1,5700,udp

Each datagram is an FGNetCtrls packet, version 27 (744 bytes, big-endian), decoded with
``flightgear-python``'s struct. Several of its fields are never filled by FlightGear 2020.3 and
carry garbage; only the flight controls (and the first engine's throttle) are read. We poll a
non-blocking socket once per frame and keep the newest packet, instead of
``flightgear_python.fg_if.CtrlsConnection``, which runs its own process and callback loop and
cannot follow our lockstep frames.
"""

from __future__ import annotations

import socket
import time
from collections.abc import Callable

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW

VERSION = 27
SIZE = 744


def decode(data: bytes) -> np.ndarray:
    """``[aileron, elevator, rudder, throttle]`` of one FGNetCtrls v27 packet (FlightGear's
    signs are ours: +elevator is stick forward, nose down), clipped to the action bounds."""
    from flightgear_python.ctrls_v27 import ctrls_struct  # construct: loaded when used

    if len(data) != SIZE:
        raise ValueError(f"{len(data)} bytes: an FGNetCtrls v{VERSION} packet has {SIZE}")
    c = ctrls_struct.parse(data)  # raises when the version word is not 27
    values = np.array([c.aileron, c.elevator, c.rudder, c.throttle[0]], dtype=np.float64)
    if not np.isfinite(values).all():
        raise ValueError(f"non-finite controls {values}")
    return np.clip(values, ACTION_LOW, ACTION_HIGH)


class CockpitReceiver:
    """The newest controls FlightGear sent to ``host:port`` (``poll``, without blocking).

    ``silent_s``: how long since the last packet (inf before the first).
    """

    def __init__(
        self, port: int, host: str = "127.0.0.1", clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.port, self.host, self.clock = port, host, clock
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self.sock.bind((host, port))
        except OSError as err:
            self.sock.close()
            raise ConfigError(
                f"flightgear device: cannot listen on {host}:{port} ({err}); give the port of "
                "FlightGear's --native-ctrls=socket,out,HZ,HOST,PORT,udp that is free here"
            ) from err
        self.sock.setblocking(False)
        self.received = self.rejected = 0
        self.last_heard = -np.inf
        self.latest: np.ndarray | None = None  # the controls as FlightGear last sent them

    def poll(self) -> np.ndarray | None:
        """The newest controls that arrived since the last poll, or None."""
        newest = None
        while True:
            try:
                newest = self.sock.recv(2048)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                continue
        if newest is None:
            return None
        try:
            values = decode(newest)
        except Exception:  # construct's errors and ours: not a controls packet
            self.rejected += 1
            return None
        self.received += 1
        self.last_heard = self.clock()
        self.latest = values
        return values

    @property
    def silent_s(self) -> float:
        return float(self.clock() - self.last_heard)

    def close(self) -> None:
        self.sock.close()
