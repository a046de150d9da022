"""The multiplayer position message, checked without FlightGear (the FlightGear test reads the
same traffic back from a real one)."""

import json
import math
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import pytest

from gymfg_il.flightgear import multiplayer as mp
from gymfg_il.flightgear import peers


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


# -- receiving ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "pose",
    [
        (37.6, -122.4, 5000.0, 10.0, 5.0, 45.0),
        (-33.9, 151.2, 120.0, -60.0, -20.0, 300.0),
        (64.0, -21.0, 38000.0, 170.0, 80.0, 180.0),
    ],
)
def test_decode_inverts_what_we_send(pose):
    packet = mp.pack("person-1", "c172p", 12.5, *pose)
    # FlightGear's own messages carry a property section after the position: ignored
    peer = peers.decode(packet + b"\0" * 661, heard_at=3.0)
    assert (peer.callsign, peer.model, peer.time_s) == (
        "person-",
        "Aircraft/c172p/Models/c172p.xml",
        12.5,
    )
    got = peer.pose
    assert got[:2] == pytest.approx(pose[:2], abs=1e-9)  # ~0.1 mm
    assert got[2] == pytest.approx(pose[2], abs=1e-3)
    assert got[3:5] == pytest.approx(pose[3:5], abs=1e-4)  # float32 angle-axis
    assert abs((got[5] - pose[5] + 180) % 360 - 180) < 1e-4


@pytest.mark.parametrize(
    "mangle, match",
    [
        (lambda b: b[:100], "shorter"),
        (lambda b: b"XXXX" + b[4:], "magic"),
        (lambda b: b[:8] + struct.pack(">I", 1) + b[12:], "message id 1"),
    ],
)
def test_decode_refuses_what_is_not_a_position_message(mangle, match):
    packet = mp.pack("x", "c172p", 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(peers.MessageError, match=match):
        peers.decode(mangle(packet))


def poll_until(link, done, deadline_s=30.0):
    """Poll ``link`` until ``done()``: what was sent has arrived (a busy machine is slow)."""
    deadline = time.monotonic() + deadline_s
    while True:
        heard = link.poll()
        if done():
            return heard
        assert time.monotonic() < deadline, (link.received, link.rejected)
        time.sleep(0.005)


def test_link_keeps_the_latest_per_callsign_and_drops_the_silent(free_udp_ports):
    now = [100.0]
    (port,) = free_udp_ports(1)
    link = peers.MultiplayerLink(
        peers.MultiplayerConfig(listen_port=port, timeout_s=2.0), clock=lambda: now[0]
    )
    sender = mp.TrafficSender([port])
    try:
        sender.send("alice", "c172p", (37.6, -122.4, 3000.0, 0.0, 0.0, 90.0))
        sender.send("bob", "f15", (37.7, -122.4, 9000.0, 0.0, 0.0, 10.0))
        sender.send("alice", "c172p", (37.6, -122.4, 3100.0, 0.0, 0.0, 90.0))
        sender.sock.sendto(b"not a message", ("127.0.0.1", port))
        heard = poll_until(link, lambda: link.received + link.rejected == 4)
        assert sorted(heard) == ["alice", "bob"]
        assert heard["alice"].altitude_ft == pytest.approx(3100.0, abs=1e-3)
        assert link.rejected == 1
        now[0] += 1.5
        sender.send("bob", "f15", (37.7, -122.4, 9000.0, 0.0, 0.0, 10.0))
        assert sorted(poll_until(link, lambda: link.received == 4)) == ["alice", "bob"]
        now[0] += 1.0  # alice silent 2.5 s, bob 1.0 s
        assert sorted(link.poll()) == ["bob"]
    finally:
        sender.close()
        link.close()


def test_config_names_bad_ports_and_timeouts():
    with pytest.raises(ValueError, match=r"listen_port.*32767"):
        peers.MultiplayerConfig(listen_port=40000)
    with pytest.raises(ValueError, match=r"send_to 127.0.0.1.*32767.*timeout_s=0"):
        peers.MultiplayerConfig(send_to=[("127.0.0.1", 99999)], timeout_s=0)


def test_listen_prints_what_it_hears(tmp_path, free_udp_ports):
    """Listens until it has printed a line (however long a busy machine takes), then is
    stopped with ctrl-C, which ends it as --seconds would."""
    (port,) = free_udp_ports(1)
    out = tmp_path / "heard.jsonl"
    cmd = [sys.executable, "-m", "gymfg_il.flightgear.multiplayer", "listen", "--port", str(port)]
    proc = subprocess.Popen(
        [*cmd, "--seconds", "120", "--json", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    sender = mp.TrafficSender([port])
    printed = []
    reader = threading.Thread(target=lambda: printed.extend(proc.stdout), daemon=True)
    reader.start()
    deadline = time.monotonic() + 100
    while not printed and proc.poll() is None and time.monotonic() < deadline:
        sender.send("person", "c172p", (37.6, -122.4, 3000.0, 15.0, 2.0, 270.0))
        time.sleep(0.05)
    sender.close()
    proc.send_signal(signal.SIGINT)
    reader.join(60)
    stderr = proc.stderr.read()
    assert proc.wait(60) == 0, stderr
    assert "Traceback" not in stderr, stderr
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert lines and lines == [json.loads(line) for line in printed]
    first = lines[0]
    assert first["callsign"] == "person" and first["model"].endswith("c172p.xml")
    assert first["altitude_ft"] == pytest.approx(3000.0, abs=0.01)
    assert (first["roll_deg"], first["heading_deg"]) == pytest.approx((15.0, 270.0), abs=1e-3)
    assert set(first) == {
        "callsign", "model", "latitude_deg", "longitude_deg", "altitude_ft",
        "roll_deg", "pitch_deg", "heading_deg",
    }  # fmt: skip
