"""The ``flightgear`` input device without FlightGear: a controls packet we encode ourselves
(FlightGear's own stream is checked in ``tests/flightgear/test_flightgear_mp.py``)."""

import socket
import struct
import time

import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.flightgear import cockpit
from gymfg_il.manual.bindings import FlightGearBindings
from gymfg_il.manual.controller import ManualController

pytestmark = pytest.mark.network


def ctrls_packet(aileron, elevator, rudder, throttle):
    """An FGNetCtrls v27 packet by hand, from net_ctrls.hxx's layout: version and padding,
    9 doubles (surfaces, trims, flaps, spoilers, speedbrake), 3 + 4x4 words, padding, then
    the throttles; the rest zero."""
    head = struct.pack(">I4x9d", 27, aileron, elevator, rudder, 0.1, 0, 0, 0, 0, 0)
    head += struct.pack(">19I4x", *([0] * 19))
    head += struct.pack(">4d", throttle, 0.5, 0.5, 0.5)
    return head + b"\0" * (cockpit.SIZE - len(head))


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_decode_reads_the_flight_controls():
    got = cockpit.decode(ctrls_packet(-0.25, 0.4, 0.1, 0.8))
    assert got == pytest.approx([-0.25, 0.4, 0.1, 0.8])
    assert cockpit.decode(ctrls_packet(-3.0, 0.0, 0.0, 2.0)) == pytest.approx([-1, 0, 0, 1])
    with pytest.raises(ValueError, match="744"):
        cockpit.decode(b"\0" * 408)
    with pytest.raises(Exception, match="27"):
        cockpit.decode(struct.pack(">I", 24) + ctrls_packet(0, 0, 0, 0)[4:])


def test_flightgear_device_acts_on_the_newest_packet():
    port = free_udp_port()
    pilot = ManualController("flightgear", flightgear=FlightGearBindings(port=port), throttle=0.6)
    obs = np.zeros(10)
    try:
        assert pilot.act(obs) == pytest.approx([0, 0, 0, 0.6])  # nothing heard yet
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as fg:
            fg.sendto(ctrls_packet(0.1, 0.2, 0.3, 0.4), ("127.0.0.1", port))
            fg.sendto(ctrls_packet(0.5, -0.3, 0.0, 0.9), ("127.0.0.1", port))
            fg.sendto(b"garbage", ("127.0.0.1", port))
            fg.sendto(ctrls_packet(0.5, -0.3, -0.2, 0.9), ("127.0.0.1", port))
            time.sleep(0.05)
        assert pilot.act(obs) == pytest.approx([0.5, -0.3, -0.2, 0.9])
        assert pilot.act(obs) == pytest.approx([0.5, -0.3, -0.2, 0.9])  # held until the next
        assert "cockpit" in pilot.status
        pilot.reset(0)  # a new episode starts from where FlightGear's stick is
        assert pilot.act(obs) == pytest.approx([0.5, -0.3, -0.2, 0.9])
    finally:
        pilot.close()


def test_a_taken_port_is_a_config_error():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        with pytest.raises(ConfigError, match=f"127.0.0.1:{port}.*native-ctrls"):
            ManualController("flightgear", flightgear=FlightGearBindings(port=port))
    with pytest.raises(ConfigError, match="port=70000"):
        FlightGearBindings(port=70000)
