"""A real FlightGear under Xvfb, fed by JSBSim through the bridge: what FlightGear shows must
follow JSBSim, read back through FlightGear's own property server."""

import os
import shutil
import socket
import subprocess
import time

import numpy as np
import pytest

from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.sim.properties import INDEX
from gymfg_il.viz.flightgear import FlightGear, find_fgfs

pytestmark = pytest.mark.flightgear


def free_port(kind=socket.SOCK_STREAM):
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def xvfb():
    if find_fgfs() is None:
        pytest.skip("FlightGear is not installed (Debian: apt-get install flightgear)")
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed (Debian: apt-get install xvfb)")
    display = f":{40 + os.getpid() % 20}"
    server = subprocess.Popen(
        ["Xvfb", display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(1)
    yield display
    server.terminate()
    server.wait(10)


def test_flightgear_follows_jsbsim(xvfb, tmp_path):
    started = time.monotonic()
    port, telnet = free_port(socket.SOCK_DGRAM), free_port()
    fg = FlightGear(port, telnet, display=xvfb, rate_hz=30)
    try:
        fg.wait_ready()
        env = AircraftEnv("heading", "c172p", agent_hz=30, views=[port], task_kwargs={"target": 60})
        pilot = controller_for(env.task, "c172p", env.dt, 0.75)
        obs, _ = env.reset(seed=0)
        pilot.reset(0)
        t0 = time.monotonic()
        for _ in range(240):  # 8 s of flight, paced to real time by the view
            obs, *_ = env.step(pilot.act(obs))
        flown = time.monotonic() - t0
        time.sleep(3)  # FlightGear renders about one frame a second in software
        state = env.world.slots[0].state
        shown = {
            p: fg.get_float(p)
            for p in (
                "/position/latitude-deg",
                "/position/longitude-deg",
                "/position/altitude-ft",
                "/orientation/roll-deg",
                "/orientation/pitch-deg",
                "/orientation/heading-deg",
            )
        }
        from PIL import ImageGrab

        shot = ImageGrab.grab(xdisplay=xvfb)
        shot.save(tmp_path / "flightgear.png")
        if os.environ.get("GYMFG_SCREENSHOT"):  # how docs/flightgear.png is made
            shot.save(os.environ["GYMFG_SCREENSHOT"])
        env.close()
    finally:
        fg.stop()
    assert 7.5 < flown < 10  # real time while a view is attached
    assert shown["/position/latitude-deg"] == pytest.approx(state[INDEX["lat_deg"]], abs=1e-4)
    assert shown["/position/longitude-deg"] == pytest.approx(state[INDEX["lon_deg"]], abs=1e-4)
    assert shown["/position/altitude-ft"] == pytest.approx(state[INDEX["altitude_ft"]], abs=3)
    assert shown["/orientation/roll-deg"] == pytest.approx(state[INDEX["roll_deg"]], abs=0.5)
    assert shown["/orientation/pitch-deg"] == pytest.approx(state[INDEX["pitch_deg"]], abs=0.5)
    heading_err = (shown["/orientation/heading-deg"] - state[INDEX["heading_deg"]] + 180) % 360
    assert abs(heading_err - 180) < 0.5
    pixels = np.asarray(shot.convert("RGB")).reshape(-1, 3)
    _, counts = np.unique(pixels // 16, axis=0, return_counts=True)
    assert len(pixels) == 768 * 1024
    assert counts.max() < 0.6 * len(pixels)  # a scene, not an empty or splash screen
    print(f"FlightGear test took {time.monotonic() - started:.0f} s")
