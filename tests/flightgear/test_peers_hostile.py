"""Whatever arrives on the multiplayer port, the listener and the env go on (red team #32.5:
one datagram at the Earth's centre raised ZeroDivisionError out of ``poll`` and ended the
run). Real datagrams to a real listener on loopback; crafted ones and seeded random ones."""

import json
import math
import socket
import struct
import subprocess
import sys
import time

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.flightgear import multiplayer as mp
from gymfg_il.flightgear import peers
from gymfg_il.sim.properties import BY_NAME, DEFAULT_OPPONENT_VIEW
from gymfg_il.tasks import DummyTask

pytestmark = pytest.mark.network

B = 6356752.314245  # WGS84 polar radius, m
FT = 0.3048


# -- geodetic on and near the axis --------------------------------------------------------


@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("x", [0.0, 1e-300, -1e-300, 1e-9])
def test_a_point_on_the_polar_axis_is_at_the_pole(sign, x):
    lat, _, alt = peers.geodetic(x, 0.0, sign * (B + 1000.0))
    assert lat == sign * 90.0
    assert alt == pytest.approx(1000.0 / FT, abs=1e-6)


@pytest.mark.parametrize("xyz", [(0.0, 0.0, 0.0), (1e-300, 0.0, 0.0), (0.0, 0.0, 1e-300)])
def test_the_earths_centre_has_a_finite_answer(xyz):
    lat, lon, alt = peers.geodetic(*xyz)
    assert all(math.isfinite(v) for v in (lat, lon, alt))
    assert -90 <= lat <= 90 and -180 <= lon <= 180
    assert alt == pytest.approx(-6378137.0 / FT, rel=0.01)  # a radius below sea level


def test_geodetic_inverts_ecef_everywhere_an_aircraft_flies():
    rng = np.random.default_rng(5)
    lats = [*rng.uniform(-90, 90, 300), 90.0, -90.0, 89.9999999, -89.9999999, 0.0]
    for lat in lats:
        lon, alt = rng.uniform(-180, 180), rng.uniform(-2000, 1e5)
        got = peers.geodetic(*mp.ecef(lat, lon, alt))
        assert got[0] == pytest.approx(lat, abs=1e-9)
        if abs(lat) < 89.99:  # at the pole every longitude is the same point
            assert got[1] == pytest.approx(lon, abs=1e-9)
        assert got[2] == pytest.approx(alt, abs=1e-4)


def test_a_pole_message_decodes_to_the_pole():
    packet = mp.pack("polar", "c172p", 1.0, 90.0, 0.0, 5000.0, 0.0, 0.0, 0.0)
    body = bytearray(packet)
    struct.pack_into(">3d", body, mp.HEADER.size + 96 + 16, 0.0, 0.0, B + 5000 * FT)
    peer = peers.decode(bytes(body))
    assert peer.lat_deg == 90.0 and peer.altitude_ft == pytest.approx(5000.0, abs=1e-6)


# -- datagrams ------------------------------------------------------------------------------


def message(position, callsign=b"crafted", angle_axis=(0.0, 0.0, 0.0), length=mp.SIZE):
    header = mp.HEADER.pack(mp.MAGIC, mp.PROTOCOL, mp.POSITION_MESSAGE, length, 100, 0, callsign)
    body = mp.BODY.pack(b"Aircraft/c172p/Models/c172p.xml", 0.0, 0.1, *position, *angle_axis,
                        *([0.0] * 12), 0)  # fmt: skip
    return header + body


CRAFTED = [  # each of these is rejected
    message((0.0, 0.0, 0.0)),  # the Earth's centre: raised ZeroDivisionError
    message((1e-300, 0.0, 0.0)),
    message((0.0, 0.0, 1e-300)),
    message((0.0, 0.0, 2.0 * B)),  # on the axis, but 20,000 km up
    message((1e308, 1e308, 1e308)),  # overflows to an infinite altitude
    message((3e6, 0.0, 0.0)),  # inside the Earth
    message((6378137.0, 0.0, 0.0), angle_axis=(float("nan"), 0.0, 0.0)),
    message((6378137.0, 0.0, 0.0), callsign=b"bad\x1b[2J"),  # ESC in a callsign
    message((6378137.0, 0.0, 0.0), callsign=b"\0" * 8),  # no callsign at all
    message((6378137.0, 0.0, 0.0), length=10_000),
]
ON_THE_AXIS = [  # and these are aircraft over the poles
    message((0.0, 0.0, B + 1000.0), callsign=b"north"),
    message((1e-300, 0.0, -(B + 1000.0)), callsign=b"south"),
]


def random_messages(n, seed):
    """``n`` datagrams with a valid header and random bodies: a third random bytes, a third
    random positions where geodesy is hardest (zeros, denormals, huge), and a third aircraft
    near or on the polar axis (their x and y zero, denormal or a nanometre)."""
    rng = np.random.default_rng(seed)
    scales = np.array([0.0, 1e-300, 1e-9, 1.0, 1e3, B, 2e7, 1e200, 1e308])
    out = []
    for i in range(n):
        callsign = rng.bytes(7) + b"\0" if i % 5 == 0 else b"r%05d\0" % i
        angles = rng.choice([0.0, 1e-30, 1.0, 3.0e38], 3) * rng.uniform(-1, 1, 3)
        if i % 3 == 0:
            header = mp.HEADER.pack(
                mp.MAGIC, mp.PROTOCOL, mp.POSITION_MESSAGE, mp.SIZE, 100, 0, callsign
            )
            out.append(header + rng.bytes(mp.BODY.size + int(rng.integers(0, 700))))
        elif i % 3 == 1:
            position = rng.choice(scales, 3) * rng.choice([-1.0, 1.0], 3)
            out.append(message(position, callsign, angles))
        else:
            lat = rng.choice([90.0, -90.0, rng.uniform(-90, 90)])
            x, y, z = mp.ecef(lat, rng.uniform(-180, 180), rng.uniform(-3000, 1.1e5))
            x, y = rng.choice([0.0, 1e-300, -1e-300, 1e-9, x], 2)
            out.append(message((x, y, z), callsign, angles))
    return out


def assert_plausible(peer):
    for name, value in zip(DEFAULT_OPPONENT_VIEW, peer.pose, strict=True):
        var = BY_NAME[name]
        assert var.low <= value <= var.high, (peer, name)


def settle(link, sent, deadline_s=30.0):
    """Poll until every datagram sent is counted, received or rejected."""
    deadline = time.monotonic() + deadline_s
    while link.received + link.rejected < sent:
        assert time.monotonic() < deadline, (link.received, link.rejected, sent)
        link.poll()
        time.sleep(0.005)


def test_the_listener_survives_every_datagram_and_counts_each(free_udp_ports):
    (port,) = free_udp_ports(1)
    link = peers.MultiplayerLink(peers.MultiplayerConfig(listen_port=port, timeout_s=600))
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    randoms = random_messages(400, seed=32)
    try:
        for packet in CRAFTED:
            tx.sendto(packet, ("127.0.0.1", port))
        settle(link, len(CRAFTED))
        assert (link.received, link.rejected) == (0, len(CRAFTED))
        for packet in ON_THE_AXIS:
            tx.sendto(packet, ("127.0.0.1", port))
        settle(link, len(CRAFTED) + 2)
        assert link.peers["north"].lat_deg == 90.0 and link.peers["south"].lat_deg == -90.0
        sent = len(CRAFTED) + len(ON_THE_AXIS)
        for i in range(0, len(randoms), 25):  # in batches: loopback buffers are finite
            for packet in randoms[i : i + 25]:
                tx.sendto(packet, ("127.0.0.1", port))
            sent += len(randoms[i : i + 25])
            settle(link, sent)
        tx.sendto(
            mp.pack("person", "c172p", 1.0, 37.6, -122.4, 3000.0, 0, 0, 90), link.sock.getsockname()
        )
        settle(link, sent + 1)
        assert link.peers["person"].altitude_ft == pytest.approx(3000.0, abs=1e-3)
        for peer in link.peers.values():
            assert_plausible(peer)
            assert peer.callsign.isprintable() and peer.model.isprintable()
        print(f"random: {link.received - 3} accepted, {link.rejected - len(CRAFTED)} rejected")
        assert link.rejected > 200  # most random bodies are not an aircraft
    finally:
        tx.close()
        link.close()


def test_an_env_with_multiplayer_keeps_stepping_through_hostile_traffic(free_udp_ports):
    listen, fg_in = free_udp_ports(2)
    config = peers.MultiplayerConfig(
        listen_port=listen, send_to=[("127.0.0.1", fg_in)], timeout_s=600
    )
    team = Team("blue", [(c172p("ego"), DummyTask)])
    env = OfflineEnv(agent_hz=30, multiplayer=config)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    person = mp.pack("person", "c172p", 1.0, 37.6, -122.4, 3000.0, 0, 0, 90)
    packets = [*CRAFTED, *ON_THE_AXIS, *random_messages(300, seed=7)]
    try:
        env.configure(team)
        env.reset(team, seed=0)
        link = env.world.link
        action = np.array([0.0, 0.0, 0.0, 0.7])
        sent = 0
        for i in range(0, len(packets), 20):
            for packet in [*packets[i : i + 20], person]:
                tx.sendto(packet, ("127.0.0.1", listen))
            sent += len(packets[i : i + 20]) + 1
            _, rows, rewards, terminated, truncated, info = env.step(action)
            assert not truncated and not terminated
        deadline = time.monotonic() + 30
        while link.received + link.rejected < sent:  # what is still in flight
            assert time.monotonic() < deadline
            _, rows, rewards, *_, info = env.step(action)
        assert link.rejected >= len(CRAFTED)
        assert {"person", "north", "south"} <= set(info["opponent_callsigns"])
        assert rows.shape == (len(info["opponent_callsigns"]), 6) and np.isfinite(rows).all()
        row = rows[info["opponent_callsigns"].index("person")]
        assert row == pytest.approx((37.6, -122.4, 3000.0, 0, 0, 90), abs=1e-4)
        assert np.isfinite(rewards).all()
    finally:
        tx.close()
        env.close()


# -- the listen diagnostic ------------------------------------------------------------------


def test_listen_into_a_folder_that_cannot_exist_is_one_error_line(tmp_path, free_udp_ports):
    (tmp_path / "a-file").write_text("")
    (port,) = free_udp_ports(1)
    out = tmp_path / "a-file" / "heard.jsonl"
    cmd = [sys.executable, "-m", "gymfg_il.flightgear.multiplayer", "listen", "--port", str(port)]
    proc = subprocess.run(
        [*cmd, "--seconds", "0.2", "--json", str(out)], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and proc.stderr.startswith("error: "), proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and str(out) in proc.stderr
    assert proc.stdout == ""


@pytest.mark.parametrize("seconds", ["nan", "-1", "0"])
def test_listen_for_no_time_is_one_error_line(seconds, free_udp_ports):
    (port,) = free_udp_ports(1)
    cmd = [sys.executable, "-m", "gymfg_il.flightgear.multiplayer", "listen", "--port", str(port)]
    proc = subprocess.run([*cmd, "--seconds", seconds], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("error: ") and "--seconds" in proc.stderr, proc.stderr
    assert json.dumps(seconds)[1:-1] in proc.stderr


def test_a_decoder_that_breaks_costs_one_datagram(monkeypatch, free_udp_ports):
    """Whatever a future decoding bug raises, ``poll`` drops that datagram and goes on."""
    (port,) = free_udp_ports(1)
    link = peers.MultiplayerLink(peers.MultiplayerConfig(listen_port=port))
    real = peers.decode

    def fragile(data, heard_at=0.0):
        if b"boom" in data:
            raise ZeroDivisionError("float division by zero")
        return real(data, heard_at)

    monkeypatch.setattr(peers, "decode", fragile)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        tx.sendto(
            mp.pack("boom", "c172p", 1.0, 37.6, -122.4, 3000.0, 0, 0, 90), ("127.0.0.1", port)
        )
        tx.sendto(
            mp.pack("person", "c172p", 1.0, 37.6, -122.4, 3000.0, 0, 0, 90), ("127.0.0.1", port)
        )
        settle(link, 2)
        assert (link.received, link.rejected, link.broken) == (1, 1, 1)
        assert sorted(link.peers) == ["person"]
    finally:
        tx.close()
        link.close()


def test_a_long_model_path_is_an_aircraft_too():
    packet = bytearray(mp.pack("person", "c172p", 1.0, 37.6, -122.4, 3000.0, 0, 0, 90))
    path = b"Aircraft/a-long-aircraft-directory-name/Models/a-long-model-file-name-too.xml"
    assert 64 < len(path) < 96
    packet[mp.HEADER.size : mp.HEADER.size + 96] = path.ljust(96, b"\0")
    assert peers.decode(bytes(packet)).model == path.decode()
    packet[mp.HEADER.size + 3] = 0x1B  # ESC
    with pytest.raises(peers.MessageError, match="printable"):
        peers.decode(bytes(packet))
