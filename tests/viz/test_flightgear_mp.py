"""A person in FlightGear and our agents in one sky, against a real FlightGear under Xvfb.

One fgfs (lightweight rendering) flies its own c172p with its own FDM, as a person would, and
sends its position by multiplayer and its controls by native-ctrls to this process. Our env
hears it as an opponent; our aircraft, flown by the ``flightgear`` device, takes FlightGear's
controls as its action; FlightGear lists our aircraft as multiplayer traffic. Controls are set
through FlightGear's property server, as a person's stick sets them. The tests run in order
and share the one fgfs; the last one stops it.
"""

import math
import os
import shutil
import socket
import subprocess
import threading
import time

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.manual.bindings import FlightGearBindings
from gymfg_il.manual.controller import ManualController
from gymfg_il.tasks import DummyTask
from gymfg_il.viz.flightgear import LIGHTWEIGHT, FlightGear, find_fgfs
from gymfg_il.viz.peers import MultiplayerConfig

pytestmark = pytest.mark.flightgear

SHOWN = {  # FlightGear's property -> the opponent row's column
    "/position/latitude-deg": 0,
    "/position/longitude-deg": 1,
    "/position/altitude-ft": 2,
    "/orientation/roll-deg": 3,
    "/orientation/pitch-deg": 4,
    "/orientation/heading-deg": 5,
}
M_PER_DEG = 111_000.0


def free_udp_ports(n):
    """``n`` consecutive-ish free UDP ports FlightGear can store (below 32768)."""
    found = []
    for port in range(24000 + os.getpid() % 7000, 32000):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                continue
        found.append(port)
        if len(found) == n:
            return found
    raise RuntimeError("no free UDP ports below 32000")


class Sky:
    """The shared fgfs and the ports around it."""

    def __init__(self, display):
        self.listen, self.fg_in, self.ctrls, self.telnet = free_udp_ports(4)
        self.fg = FlightGear(
            None,  # FlightGear flies its own c172p
            self.telnet,
            display=display,
            geometry="320x240",
            multiplayer_port=self.fg_in,
            multiplayer_out=self.listen,
            callsign="person",
            extra=(
                *LIGHTWEIGHT,
                f"--native-ctrls=socket,out,30,127.0.0.1,{self.ctrls},udp",
                "--in-air",
                "--altitude=4000",
                "--vc=100",
                "--heading=280",
            ),
        )
        self.fg.wait_ready(240)  # the first start builds a navaid cache

    def set(self, prop, value):
        self.fg.set(prop, value)

    def env(self, timeout_s=2.0):
        config = MultiplayerConfig(
            listen_port=self.listen, send_to=[("127.0.0.1", self.fg_in)], timeout_s=timeout_s
        )
        return OfflineEnv(agent_hz=30, multiplayer=config)

    def pilot(self):
        return ManualController("flightgear", flightgear=FlightGearBindings(port=self.ctrls))


@pytest.fixture(scope="module")
def sky():
    if find_fgfs() is None:
        pytest.skip("FlightGear is not installed (Debian: apt-get install flightgear)")
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (Debian: apt-get install xvfb)")
    display = f":{60 + os.getpid() % 20}"
    xvfb = subprocess.Popen(
        ["Xvfb", display, "-screen", "0", "640x480x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1)
    sky = None
    try:
        sky = Sky(display)
        yield sky
    finally:
        if sky is not None:
            sky.fg.stop()
        xvfb.terminate()
        xvfb.wait(10)


TEAM = Team("blue", [(c172p("ego"), DummyTask)])


def fly(env, pilot, obs, seconds, seen=None):
    """Step the env in real time for ``seconds``, FlightGear's controls flying ours;
    ``seen`` collects (time, opponent row) per step."""
    for _ in range(round(seconds * 30)):
        obs, rows, *_, info = env.step(pilot.act(obs[0]))
        assert info["opponent_callsigns"] == ["person"], info
        if seen is not None:
            seen.append((time.perf_counter(), rows[0].copy()))
    return obs


def read_properties(sky, stop, reads):
    """FlightGear's own values, each bracketed by when we asked and when it answered."""
    while not stop.is_set():
        for prop in SHOWN:
            asked = time.perf_counter()
            value = sky.fg.get_float(prop)
            reads.append((prop, asked, time.perf_counter(), value))


def bracket_errors(reads, seen):
    """For each property read, the smallest difference to a row we held between asking and
    a step after the answer: FlightGear answers and sends its position in one main-loop
    frame, so the row of that frame is among them."""
    errors = {p: [] for p in SHOWN}
    times = np.array([t for t, _ in seen])
    rows = np.array([r for _, r in seen])
    for prop, asked, answered, value in reads:
        near = rows[(times >= asked) & (times <= answered + 0.1), SHOWN[prop]]
        if len(near):
            diff = near - value
            if "heading" in prop:
                diff = (diff + 180) % 360 - 180
            errors[prop].append(np.abs(diff).min())
    return {p: np.array(e) for p, e in errors.items()}


def test_a_flightgear_aircraft_is_an_opponent_and_our_controls_come_from_its_cockpit(sky):
    env, pilot = sky.env(), sky.pilot()
    seen, reads, stop = [], [], threading.Event()
    try:
        sky.set("/controls/flight/aileron", 0.15)  # bank right
        env.configure(TEAM)  # listening from here on
        time.sleep(0.3)
        obs, _ = env.reset(TEAM, seed=0)
        reader = threading.Thread(target=read_properties, args=(sky, stop, reads))
        reader.start()
        obs = fly(env, pilot, obs, 2.5, seen)
        sky.set("/controls/flight/aileron", -0.3)  # and back to the left
        obs = fly(env, pilot, obs, 2.5, seen)
        stop.set()
        reader.join()
        sky.set("/controls/flight/aileron", 0.0)
        fps = sky.fg.get_float("/sim/frame-rate")
        # a control set in FlightGear is our action within 2 steps of FlightGear sending it
        # (it sends once a frame): counted from FlightGear holding it (its property server
        # answers in the frame that set it)
        latency = []
        for value in (0.2, -0.15, 0.05):
            sky.set("/controls/flight/elevator", value)
            assert sky.fg.get_float("/controls/flight/elevator") == pytest.approx(value)
            held = time.perf_counter()
            for steps in range(1, 100):
                obs, *_ = env.step(action := pilot.act(obs[0]))
                if action[1] == pytest.approx(value):
                    latency.append((steps, round(time.perf_counter() - held, 3)))
                    break
        models = sky.fg.get("/ai/models/multiplayer[0]/callsign")
    finally:
        stop.set()
        sky.set("/controls/flight/aileron", 0.0)
        sky.set("/controls/flight/elevator", 0.0)
        pilot.close()
        env.close()
    errors = bracket_errors(reads, seen)
    scale = (M_PER_DEG, M_PER_DEG * np.cos(np.radians(37.6)), 0.3048, 1, 1, 1)
    named = [(p.rsplit("/", 1)[1], errors[p] * k) for p, k in zip(SHOWN, scale, strict=True)]
    worst = {name: e.max() for name, e in named}
    median = {name: np.median(e) for name, e in named}
    rolls = [v for p, _, _, v in reads if p.endswith("roll-deg")]
    print(f"FlightGear at {fps:g} fps, {len(reads)} property reads; decode error (m, deg)")
    print("worst", {k: round(v, 3) for k, v in worst.items()})
    print("median", {k: round(v, 4) for k, v in median.items()})
    print(f"roll {min(rolls):.1f}..{max(rolls):.1f} deg; controls latency {latency} (steps, s)")
    assert all(len(e) >= 2 for e in errors.values())
    assert max(list(worst.values())[:3]) < 30  # metres
    assert max(list(worst.values())[3:]) < 2  # degrees
    assert max(rolls) - min(rolls) > 5  # it banked, and we followed
    frame_steps = math.ceil(30 / max(fps, 1))
    assert len(latency) == 3 and max(s for s, _ in latency) <= 2 + frame_steps
    assert models == "ego"  # our agent is multiplayer traffic in FlightGear


def test_a_manual_session_records_what_flightgear_commands(sky, tmp_path):
    from gymfg_il.collectors.manual import ManualSession
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.learning.data import load_frames

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    def key(k):
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=k, mod=0, unicode="", scancode=0))

    def on_frame(frame, session):
        if frame == 1:
            key(pygame.K_SPACE)
        elif frame == 20:
            sky.set("/controls/flight/rudder", 0.3)
        elif frame == 40:
            key(pygame.K_e)
        elif frame == 45:
            key(pygame.K_q)

    sky.set("/controls/flight/rudder", -0.2)
    spec = FlightSpec.solo("c172p", "altitude", episode_time_s=3, agent_hz=30)
    session = ManualSession(
        spec,
        tmp_path,
        device="flightgear",
        bindings={"flightgear": {"port": sky.ctrls}},
        on_frame=on_frame,
        draw=False,
        pilot_view=None,
    )
    stats = session.run(max_frames=200)
    sky.set("/controls/flight/rudder", 0.0)
    assert stats.saved == 1
    rudder = load_frames(tmp_path / "dataset").action[:, 2]
    # until FlightGear's first packet reaches the new session the stick reads centred
    assert rudder[8:18] == pytest.approx([-0.2] * 10)
    assert rudder[-5:] == pytest.approx([0.3] * 5)


def test_a_flightgear_that_stops_is_dropped(sky):
    env, pilot = sky.env(timeout_s=1.0), sky.pilot()
    try:
        env.configure(TEAM)
        time.sleep(0.3)
        obs, rows = env.reset(TEAM, seed=0)
        for _ in range(3):
            obs, rows, *_, info = env.step(pilot.act(obs[0]))
        assert info["opponent_callsigns"] == ["person"]
        sky.fg.stop()
        stopped = time.perf_counter()
        while time.perf_counter() - stopped < 5 and rows.shape[0]:
            obs, rows, *_, info = env.step(pilot.act(obs[0]))
        gone_after = time.perf_counter() - stopped
    finally:
        pilot.close()
        env.close()
    print(f"dropped {gone_after:.2f} s after fgfs stopped")
    assert rows.shape == (0, 6) and info["opponent_callsigns"] == []
    assert gone_after < 3
