"""The multiplayer position message, checked without FlightGear (the FlightGear test reads the
same traffic back from a real one)."""

import math
import socket
import struct

import pytest

from gymfg_il.viz import multiplayer as mp


def euler_from(angle_axis, lat_deg, lon_deg):
    """Invert the message's orientation: (roll, pitch, heading) in degrees."""
    angle = math.sqrt(sum(v * v for v in angle_axis))
    axis = [v / angle for v in angle_axis] if angle else [1.0, 0.0, 0.0]
    s = math.sin(angle / 2)
    q = (math.cos(angle / 2), axis[0] * s, axis[1] * s, axis[2] * s)
    w, x, y, z = mp._local_frame(math.radians(lat_deg), math.radians(lon_deg))
    w, x, y, z = mp._mul((w, -x, -y, -z), q)
    roll = math.atan2(2 * (y * z + w * x), w * w - x * x - y * y + z * z)
    pitch = -math.asin(max(-1.0, min(1.0, 2 * (x * z - w * y))))
    heading = math.atan2(2 * (x * y + w * z), w * w + x * x - y * y - z * z)
    return math.degrees(roll), math.degrees(pitch), math.degrees(heading) % 360


@pytest.mark.parametrize(
    "lat, lon, roll, pitch, heading",
    [
        (37.6, -122.4, 10, 5, 45),
        (-33.9, 151.2, -60, -20, 300),
        (0, 0, 0, 0, 0),
        (64, -21, 170, 80, 180),
    ],
)
def test_orientation_round_trips(lat, lon, roll, pitch, heading):
    got = euler_from(mp.orientation(lat, lon, roll, pitch, heading), lat, lon)
    assert got == pytest.approx((roll, pitch, heading), abs=1e-6)


def test_ecef_matches_wgs84():
    assert mp.ecef(0, 0, 0) == pytest.approx((6378137.0, 0, 0))
    assert mp.ecef(90, 0, 0)[2] == pytest.approx(6356752.314, abs=1e-3)  # polar radius
    assert mp.ecef(0, 90, 1000 / 0.3048)[1] == pytest.approx(6379137.0)


def test_message_layout_and_delivery():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as rx:
        for port in range(21000, 32000):  # FlightGear's range, below the ephemeral ports
            try:
                rx.bind(("127.0.0.1", port))
                break
            except OSError:
                continue
        rx.settimeout(5)
        sender = mp.TrafficSender([rx.getsockname()[1]])
        sender.send("wingman-two", "f15", (37.6, -122.4, 5000.0, 0.0, 0.0, 90.0))
        data = rx.recv(1024)
        sender.close()
    assert len(data) == mp.SIZE == 232
    magic, version, kind, length, _, _, callsign = mp.HEADER.unpack_from(data)
    assert (magic, version, kind, length) == (0x46474653, 0x00010001, 7, 232)
    assert callsign.rstrip(b"\0") == b"wingman"  # 7 characters and a zero
    model = struct.unpack_from(">96s", data, mp.HEADER.size)[0].rstrip(b"\0")
    assert model == b"AI/Aircraft/F-15/Models/F-15.xml"
    assert mp.model_path("not-a-model") == "Aircraft/ufo/Models/ufo.xml"


def test_ports_flightgear_cannot_store_are_refused():
    with pytest.raises(ValueError, match="32767"):
        mp.TrafficSender([40000])
