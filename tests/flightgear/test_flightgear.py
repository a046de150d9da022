"""A real FlightGear under Xvfb, fed by JSBSim through the bridge: what FlightGear shows must
follow JSBSim, read back through FlightGear's own property server."""

import os
import socket
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.aircraft import c172p
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs.offline import OfflineEnv
from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.launcher import FlightGear, FlightGearError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks import LevelFlightTask
from gymfg_il.tasks.geometry import offset_position

sys.path.insert(0, str(Path(__file__).parent))
from waiting_fg import needs_flightgear, wait_flightgear_time

pytestmark = pytest.mark.flightgear


def free_port(kind=socket.SOCK_STREAM):
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def display(xvfb):
    needs_flightgear()
    with xvfb("1024x768x24") as display:
        yield display


def wing_ahead(rng, aircraft):
    """The wingman 600 ft straight ahead of the viewer, same heading, altitude and speed."""
    (_, wing), (_, ego) = aircraft
    ic = InitialConditions(
        altitude_ft=ego.profile.cruise_altitude_ft, airspeed_kts=ego.profile.cruise_kts
    )
    lat, lon = offset_position(ic.latitude_deg, ic.longitude_deg, 600.0, 0.0)
    return {ego.callsign: ic, wing.callsign: replace(ic, latitude_deg=lat, longitude_deg=lon)}


def test_flightgear_follows_jsbsim(display, tmp_path, free_udp_ports):
    """One view follows "ego" through the native-fdm stream; its wingman flies in it as
    multiplayer traffic. Both, and a healthy engine with fuel, are read back from FlightGear."""
    started = time.monotonic()
    port, telnet, (traffic,) = free_port(socket.SOCK_DGRAM), free_port(), free_udp_ports(1)
    fg = FlightGear(port, telnet, display=display, rate_hz=30, multiplayer_port=traffic)
    try:
        fg.wait_ready()
        team = Team("blue", [(c172p("wing"), LevelFlightTask), (c172p("ego"), LevelFlightTask)])
        env = OfflineEnv(
            agent_hz=30, scenario=wing_ahead, views={"ego": [port]}, traffic={"ego": [traffic]}
        )
        obs, _ = env.reset(team, seed=0)
        pilots = [controller_for(s.task, "c172p", env.dt, 0.75) for s in env.world.slots]
        for pilot in pilots:
            pilot.reset(0)
        t0 = time.monotonic()
        for _ in range(240):  # 8 s of flight, paced to real time by the view
            obs, *_ = env.step(np.hstack([p.act(o) for p, o in zip(pilots, obs, strict=True)]))
        flown = time.monotonic() - t0
        # FlightGear draws a few frames a second in software (fewer on a busy machine), and
        # shows multiplayer traffic a little behind its clock: 3 s of that clock
        wait_flightgear_time(fg, 3.0)
        wing, ego = (s.state for s in env.world.slots)
        fuel_gal = env.world.slots[1].sim.fdm["propulsion/tank[0]/contents-lbs"] / 6.0
        shown = {p: fg.get_float(p) for p in (*SHOWN, "/consumables/fuel/tank[0]/level-gal_us")}
        mp = "/ai/models/multiplayer[0]"
        # an AI model names its heading true-heading-deg
        other = {p: fg.get_float(mp + p.replace("/heading", "/true-heading")) for p in SHOWN}
        other_callsign = fg.get(mp + "/callsign")
        from PIL import ImageGrab

        shot = ImageGrab.grab(xdisplay=display)
        shot.save(tmp_path / "flightgear.png")
        if os.environ.get("GYMFG_SCREENSHOT"):  # how docs/images/flightgear.png is made
            shot.save(os.environ["GYMFG_SCREENSHOT"])
        log = fg.log_path.read_text(errors="replace")
        env.close()
    finally:
        fg.stop()
    assert 7.5 < flown < 10  # real time while a view is attached
    assert_shows(shown, ego)
    assert other_callsign == "wing"
    assert_shows(other, wing)
    assert shown["/consumables/fuel/tank[0]/level-gal_us"] == pytest.approx(fuel_gal, abs=0.05)
    assert fuel_gal > 10
    assert "Out of fuel" not in log
    pixels = np.asarray(shot.convert("RGB")).reshape(-1, 3)
    _, counts = np.unique(pixels // 16, axis=0, return_counts=True)
    assert len(pixels) == 768 * 1024
    assert counts.max() < 0.6 * len(pixels)  # a scene, not an empty or splash screen
    print(f"FlightGear test took {time.monotonic() - started:.0f} s")


SHOWN = (
    "/position/latitude-deg",
    "/position/longitude-deg",
    "/position/altitude-ft",
    "/orientation/roll-deg",
    "/orientation/pitch-deg",
    "/orientation/heading-deg",
)


def assert_shows(shown, state):
    """FlightGear's view of an aircraft matches its JSBSim state."""
    values = dict(zip(SHOWN, shown.values(), strict=False))
    assert values[SHOWN[0]] == pytest.approx(state[INDEX["lat_deg"]], abs=1e-4)
    assert values[SHOWN[1]] == pytest.approx(state[INDEX["lon_deg"]], abs=1e-4)
    assert values[SHOWN[2]] == pytest.approx(state[INDEX["altitude_ft"]], abs=3)
    assert values[SHOWN[3]] == pytest.approx(state[INDEX["roll_deg"]], abs=0.5)
    assert values[SHOWN[4]] == pytest.approx(state[INDEX["pitch_deg"]], abs=0.5)
    heading_err = (values[SHOWN[5]] - state[INDEX["heading_deg"]] + 180) % 360
    assert abs(heading_err - 180) < 0.5


def test_traffic_ports_above_what_flightgear_stores_are_refused():
    with pytest.raises(ConfigError, match=r"1\.\.32767"):
        OfflineEnv(traffic={"ego": [40000]})
    with pytest.raises(FlightGearError, match=r"1\.\.32767"):
        FlightGear(5500, 5501, multiplayer_port=50000)
