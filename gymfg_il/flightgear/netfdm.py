"""FlightGear's native FDM packet (``net_fdm``, version 24, FlightGear 2020.3), filled from a
JSBSim instance and sent over UDP.

JSBSim's own FLIGHTGEAR output re-creates its socket at every reset and sends no engine or
fuel data beyond what the model maps; this sender keeps one socket per view for the life of
the environment and fills engine, fuel, gear and surface fields so FlightGear shows a healthy
aircraft. Layout (network byte order): version, padding, lon/lat/alt (double), 6 + 11 + 3 + 2
floats of attitude, rates, speeds, accelerations and warnings, engines (4), tanks (4),
wheels (3), time, warp, visibility and 10 control-surface floats: 408 bytes.
"""

from __future__ import annotations

import contextlib
import socket
import struct
from collections.abc import Sequence
from typing import Any

from gymfg_il.units import FT_TO_M

VERSION = 24
FORMAT = ">I4x3d6f11f3f2fI4I36fI4fI3I9fIif10f"
SIZE = struct.calcsize(FORMAT)
assert SIZE == 408, SIZE

# engine gauges FlightGear shows that the view need not take from JSBSim, 4 engines each:
# fuel pressure (psi); after the EGT, cylinder head temperature (degF), manifold pressure
# (inHg), turbine inlet temperature, oil temperature (degF) and oil pressure (psi)
_FUEL_PRESSURE = (30.0,) * 4
_AFTER_EGT = (300.0,) * 4 + (20.0,) * 4 + (0.0,) * 4 + (180.0,) * 4 + (60.0,) * 4
# the 3 wheels' steering and compression, then cur_time (0: FlightGear keeps its own time
# of day) and warp
_AFTER_GEAR = (0.0,) * 3 + (0.0,) * 3 + (0, 0)


def _get(fdm: Any, prop: str, default: float = 0.0) -> float:
    try:
        return float(fdm[prop])
    except (KeyError, RuntimeError):
        return default


def pack(fdm: Any, engines: int, visibility_m: float = 20000.0) -> bytes:
    """One packet describing the JSBSim instance ``fdm`` now."""
    n = min(engines, 4)
    state, rpm, fuel_flow, egt = _engines(fdm, n)
    tanks = [_get(fdm, f"propulsion/tank[{i}]/contents-lbs") / 6.0 for i in range(4)]  # US gal
    n_tanks = sum(1 for t in tanks if t > 0) or 1
    wow = [int(_get(fdm, f"gear/unit[{i}]/WOW")) for i in range(3)]
    down = _get(fdm, "gear/gear-pos-norm")  # a wheel's position where it has none of its own
    gear = [_get(fdm, f"gear/unit[{i}]/pos-norm", down) for i in range(3)]
    return struct.pack(
        FORMAT,
        VERSION,
        *_motion(fdm),
        n,
        *state,
        *rpm,
        *fuel_flow,
        *_FUEL_PRESSURE,
        *egt,
        *_AFTER_EGT,
        n_tanks,
        *tanks,
        3,
        *wow,
        *gear,
        *_AFTER_GEAR,
        visibility_m,
        *_surfaces(fdm),
    )


def _engines(fdm: Any, n: int) -> tuple[list[int], list[float], list[float], list[float]]:
    """The first ``n`` engines' (state, rpm, fuel flow in gal/h, EGT in degF), 4 each."""
    rpm, fuel_flow, egt, state = [0.0] * 4, [0.0] * 4, [0.0] * 4, [0] * 4
    for i in range(n):
        base = f"propulsion/engine[{i}]/"
        rpm[i] = _get(fdm, base + "engine-rpm", _get(fdm, base + "n2"))
        fuel_flow[i] = _get(fdm, base + "fuel-flow-rate-pps") * 3600.0 / 6.0  # gal/h (avgas)
        egt[i] = _get(fdm, base + "egt-degF", 1200.0)
        state[i] = 2 if _get(fdm, base + "set-running", 1.0) else 0
    return state, rpm, fuel_flow, egt


def _motion(fdm: Any) -> tuple[float, ...]:
    """Position (lon, lat, alt and agl in m), attitude, aerodynamic angles, body rates,
    speeds, pilot accelerations and the stall warning and slip (FlightGear's order)."""
    g = fdm.__getitem__
    return (
        g("position/long-gc-rad"),
        g("position/lat-geod-rad"),
        g("position/h-sl-ft") * FT_TO_M,
        g("position/h-agl-ft") * FT_TO_M,
        g("attitude/phi-rad"),
        g("attitude/theta-rad"),
        g("attitude/psi-rad"),
        g("aero/alpha-rad"),
        g("aero/beta-rad"),
        g("velocities/p-rad_sec"),
        g("velocities/q-rad_sec"),
        g("velocities/r-rad_sec"),
        g("velocities/vc-kts"),
        g("velocities/h-dot-fps"),
        g("velocities/v-north-fps"),
        g("velocities/v-east-fps"),
        g("velocities/v-down-fps"),
        g("velocities/u-fps"),
        g("velocities/v-fps"),
        g("velocities/w-fps"),
        g("accelerations/a-pilot-x-ft_sec2"),
        g("accelerations/a-pilot-y-ft_sec2"),
        g("accelerations/a-pilot-z-ft_sec2"),
        0.0,
        g("aero/beta-deg"),
    )


def _surfaces(fdm: Any) -> tuple[float, ...]:
    """The 10 control-surface fields: elevator, its trim tab, left and right flap, left and
    right aileron, rudder, nose wheel, speedbrake, spoilers."""
    flaps = _get(fdm, "fcs/flap-pos-norm")
    return (
        _get(fdm, "fcs/elevator-pos-rad"),
        0.0,
        flaps,
        flaps,
        _get(fdm, "fcs/left-aileron-pos-rad"),
        _get(fdm, "fcs/right-aileron-pos-rad"),
        _get(fdm, "fcs/rudder-pos-rad"),
        0.0,
        0.0,
        0.0,
    )


class FlightGearSender:
    """One UDP socket per aircraft, kept for the life of the environment, to every port that
    shows it (several views of one aircraft are several FlightGear instances)."""

    def __init__(self, ports: Sequence[int], host: str = "127.0.0.1") -> None:
        self.targets = [(host, int(p)) for p in ports]
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sent = 0

    def send(self, fdm: Any, engines: int) -> None:
        packet = pack(fdm, engines)
        for target in self.targets:
            # nobody listening yet is fine: a view may come later
            with contextlib.suppress(OSError):
                self.sock.sendto(packet, target)
        self.sent += 1

    def close(self) -> None:
        self.sock.close()
