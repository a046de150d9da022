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
import select
import socket
import sys
import threading
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.flightgear.launcher import LIGHTWEIGHT, FlightGear
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.manual.bindings import FlightGearBindings
from gymfg_il.manual.controller import ManualController
from gymfg_il.tasks import DummyTask

sys.path.insert(0, str(Path(__file__).parent))
from waiting_fg import DEADLINE_S, needs_flightgear, wait_until

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


class Sky:
    """The shared fgfs and the ports around it."""

    def __init__(self, display, ports):
        self.listen, self.fg_in, self.ctrls, self.telnet = ports
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
        self.fg.wait_ready(300)  # the first start builds a navaid cache
        self.wait_streaming()

    def wait_streaming(self, packets=10, gap_s=1.0):
        """Wait until fgfs sends its position and its controls steadily: ``packets`` in a row
        on each, none more than ``gap_s`` after the last. On a busy machine the first seconds
        after its scenery loads hold stalls of ~2 s, longer than an env's ``timeout_s``."""
        socks = []
        for port in (self.listen, self.ctrls):
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.bind(("127.0.0.1", port))
            socks.append(sock)
        try:
            run, last = dict.fromkeys(socks, 0), dict.fromkeys(socks, time.monotonic())
            deadline = time.monotonic() + DEADLINE_S
            while min(run.values()) < packets:
                assert time.monotonic() < deadline, f"fgfs never streamed steadily: {run}"
                ready, _, _ = select.select(socks, [], [], 0.1)
                now = time.monotonic()
                for sock in ready:
                    sock.recv(4096)
                    run[sock] = run[sock] + 1 if now - last[sock] <= gap_s else 1
                    last[sock] = now
        finally:
            for sock in socks:
                sock.close()

    def set(self, prop, value):
        self.fg.set(prop, value)

    def env(self, timeout_s=30.0):
        """An env hearing the shared fgfs. The default keeps a FlightGear that stalls (a busy
        machine's fgfs has gone silent for over 2 s mid-flight) in the sky; only the test of
        dropping a silent FlightGear asks for a short ``timeout_s``."""
        config = MultiplayerConfig(
            listen_port=self.listen, send_to=[("127.0.0.1", self.fg_in)], timeout_s=timeout_s
        )
        return OfflineEnv(agent_hz=30, multiplayer=config)

    def pilot(self):
        return ManualController("flightgear", flightgear=FlightGearBindings(port=self.ctrls))


@pytest.fixture(scope="module")
def sky(xvfb, free_udp_ports):
    needs_flightgear()
    with xvfb("640x480x24") as display:
        sky = None
        try:
            sky = Sky(display, free_udp_ports(4))
            yield sky
        finally:
            if sky is not None:
                sky.fg.stop()


TEAM = Team("blue", [(c172p("ego"), DummyTask)])


def hear_the_person(env):
    """Reset until the env hears FlightGear's aircraft (a reset listens, as a step does)."""
    return wait_until(
        lambda: (r := env.reset(TEAM, seed=0))[1].shape[0] and r, "fgfs's multiplayer traffic"
    )


def fly(env, pilot, obs, seconds, seen=None, enough=lambda: True):
    """Step the env in real time for ``seconds`` and on until ``enough()``, FlightGear's
    controls flying ours; ``seen`` collects (time, opponent row) per step."""
    deadline = time.monotonic() + seconds + DEADLINE_S
    steps = 0
    while steps < round(seconds * 30) or not enough():
        assert time.monotonic() < deadline, "not enough within the deadline"
        obs, rows, *_, info = env.step(pilot.act(obs[0]))
        assert info["opponent_callsigns"] == ["person"], info
        if seen is not None:
            seen.append((time.perf_counter(), rows[0].copy()))
        steps += 1
    return obs


def each_read_twice_since(reads, start):
    """``enough`` for ``fly``: every property answered twice since ``len(reads) == start``
    (FlightGear answers a read in about two of its frames: ~0.4 s on a busy machine)."""
    return lambda: min(Counter(p for p, *_ in reads[start:])[p] for p in SHOWN) >= 2


def steps_per_frame(sky):
    """FlightGear's longest frame of the last second (its own measure), in our 30 Hz steps."""
    return math.ceil(sky.fg.get_float("/sim/frame-latency-max-ms") * 30 / 1000)


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
        obs, _ = hear_the_person(env)
        reader = threading.Thread(target=read_properties, args=(sky, stop, reads))
        reader.start()
        obs = fly(env, pilot, obs, 2.5, seen, each_read_twice_since(reads, 0))
        sky.set("/controls/flight/aileron", -0.3)  # and back to the left
        obs = fly(env, pilot, obs, 2.5, seen, each_read_twice_since(reads, len(reads)))
        stop.set()
        reader.join()
        sky.set("/controls/flight/aileron", 0.0)
        fps = sky.fg.get_float("/sim/frame-rate")
        # a control set in FlightGear is our action within 2 steps of FlightGear sending it
        # (it sends once a frame): counted from FlightGear holding it (its property server
        # answers in the frame that set it); a frame is FlightGear's longest in the second
        # around the change, by its own measure (a busy machine draws 3-5 uneven frames a
        # second)
        latency = []
        for value in (0.2, -0.15, 0.05):
            frame_steps = steps_per_frame(sky)
            sky.set("/controls/flight/elevator", value)
            assert sky.fg.get_float("/controls/flight/elevator") == pytest.approx(value)
            held = time.perf_counter()
            for steps in range(1, 300):
                obs, *_ = env.step(action := pilot.act(obs[0]))
                if action[1] == pytest.approx(value):
                    took = round(time.perf_counter() - held, 3)
                    frame_steps = max(frame_steps, steps_per_frame(sky))
                    latency.append((steps, took, frame_steps))
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
    print(f"roll {min(rolls):.1f}..{max(rolls):.1f} deg; controls latency {latency}")
    print("(steps, s, steps in FlightGear's longest frame)")
    assert all(len(e) >= 2 for e in errors.values())
    assert max(list(worst.values())[:3]) < 30  # metres
    assert max(list(worst.values())[3:]) < 2  # degrees
    assert max(rolls) - min(rolls) > 5  # it banked, and we followed
    assert len(latency) == 3 and all(s <= 2 + frame for s, _, frame in latency)
    assert models == "ego"  # our agent is multiplayer traffic in FlightGear


def test_a_manual_session_records_what_flightgear_commands(sky, tmp_path):
    """Keys and FlightGear's stick follow what the session has heard, not fixed frames: a
    busy machine's FlightGear sends a packet every 0.2-0.4 s, and the session starting an
    episode (its dataset helper's imports) can stall it for longer."""
    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig
    from gymfg_il.learning.data import load_frames

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    def key(k):
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=k, mod=0, unicode="", scancode=0))

    def rudder_heard(session, value):
        latest = session.stages.human.cockpit.latest
        return latest is not None and latest[2] == pytest.approx(value)

    at = {}  # frame -> what happened at its start (the step of frame f is row f - 1)

    def on_frame(frame, session):
        if frame == 1:
            key(pygame.K_SPACE)  # the episode starts: a step every frame from here
        elif "heard" not in at and frame > 1 and rudder_heard(session, -0.2):
            at["heard"] = frame  # FlightGear's -0.2 flies every step from here
        elif "heard" in at and "set" not in at and frame >= at["heard"] + 10:
            sky.set("/controls/flight/rudder", 0.3)
            at["set"] = frame
        elif "set" in at and "moved" not in at and rudder_heard(session, 0.3):
            at["moved"] = frame
        elif "moved" in at and frame == at["moved"] + 5:
            key(pygame.K_e)  # saved: the last 5 steps flew 0.3
        elif "moved" in at and frame == at["moved"] + 10:
            key(pygame.K_q)

    sky.set("/controls/flight/rudder", -0.2)
    cfg = ManualConfig(
        task="altitude",
        episode_time_s=120,
        agent_hz=30,
        episodes=0,
        seed=0,
        out=tmp_path,
        device="flightgear",
        flightgear={"port": sky.ctrls},
        pilot_view="none",
    )
    session = ManualSession(cfg, on_frame, draw=False)
    stats = session.run(max_frames=30 * 110)  # the deadline: quit comes long before
    sky.set("/controls/flight/rudder", 0.0)
    print(f"manual session: {at} (frames)")
    assert stats.saved == 1 and set(at) == {"heard", "set", "moved"}
    rudder = load_frames(tmp_path / "dataset").action[:, 2]
    assert len(rudder) == at["moved"] + 4  # frames 1 .. moved + 4 stepped
    # until FlightGear's first packet reaches the new session the stick reads centred
    assert rudder[at["heard"] - 1 : at["set"] - 1] == pytest.approx([-0.2] * 10)
    assert rudder[-5:] == pytest.approx([0.3] * 5)


def test_a_flightgear_that_stops_is_dropped(sky):
    env, pilot = sky.env(timeout_s=1.0), sky.pilot()
    try:
        env.configure(TEAM)
        obs, rows = hear_the_person(env)
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
