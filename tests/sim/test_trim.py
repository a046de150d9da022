"""Trimmed starts: hands-off flight from a reset stays level, trims reproduce, untrimmed
starts stay available, and an aircraft that cannot be trimmed says where."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from gymfg_il.aircraft import PROFILES
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.simulation import Simulation
from gymfg_il.sim.trim import trim_for


def _hands_off(sim: Simulation, seconds: float = 5.0) -> tuple[float, float]:
    """Worst altitude change (ft) and pitch rate (rad/s), at the agent rate, flying the
    trim's controls (the start action: the trim's surfaces and throttle)."""
    assert sim.trim is not None
    fdm = sim.fdm
    h0, worst_h, worst_q = fdm["position/h-sl-ft"], 0.0, 0.0
    for _ in range(round(seconds * sim.agent_hz)):
        sim.apply(*sim.start_action)
        worst_h = max(worst_h, abs(fdm["position/h-sl-ft"] - h0))
        worst_q = max(worst_q, abs(fdm["velocities/q-rad_sec"]))
    return worst_h, worst_q


@pytest.mark.parametrize("model", ["c172p", "f15", "A320"])
def test_hands_off_flight_from_a_reset_holds_altitude_and_pitch(model):
    profile, sim = PROFILES[model], Simulation(model)
    rng = np.random.default_rng(11)
    for _ in range(3):  # starts drawn as the tasks draw them: between trim grid points
        ic = InitialConditions(
            altitude_ft=profile.cruise_altitude_ft + float(rng.uniform(-500, 500)),
            airspeed_kts=profile.cruise_kts * float(rng.uniform(0.95, 1.05)),
            heading_deg=float(rng.uniform(0, 360)),
            trimmed=True,
        )
        sim.reset(ic, profile.cruise_throttle)
        worst_h, worst_q = _hands_off(sim)
        # the issue asked for 50 ft and 0.02 rad/s; the engines start in their steady state
        # at the trim's throttle (JSBSim starts them at full throttle's: the c172p then
        # pitched at 0.019-0.021 rad/s), and all three do far better
        assert worst_h < (5.0 if model == "c172p" else 2.0), (model, ic, worst_h)
        assert worst_q < (0.011 if model == "c172p" else 0.003), (model, ic, worst_q)


def test_untrimmed_starts_remain_and_show_the_transient():
    sim = Simulation("c172p")
    sim.reset(InitialConditions(trimmed=False), 0.75)
    assert sim.trim is None
    fdm, q = sim.fdm, 0.0
    for _ in range(20):
        sim.apply(0.0, 0.0, 0.0, 0.75)
        q = max(q, abs(fdm["velocities/q-rad_sec"]))
    assert q > 0.1  # the transient a trimmed start removes
    # trims do not leak from a trimmed episode into an untrimmed one on a reused instance
    sim.reset(InitialConditions(trimmed=True), 0.75)
    sim.reset(InitialConditions(trimmed=False), 0.75)
    assert fdm["fcs/pitch-trim-cmd-norm"] == 0.0


def test_a_trimmed_start_is_straight_and_level():
    with pytest.raises(ConfigError, match="trimmed=False"):
        InitialConditions(roll_deg=30.0, trimmed=True)
    InitialConditions(roll_deg=30.0, trimmed=False)  # an untrimmed upset start, on purpose
    assert InitialConditions().trimmed  # trimmed by default


def test_trims_are_the_same_in_a_fresh_process():
    """A grid point trims alike whatever was trimmed before it: resets reproduce across
    worker processes."""
    trim_for("c172p", 7000.0, 95.0, 120, Simulation)  # other grid points first, here
    here = trim_for("c172p", 5250.0, 104.0, 120, Simulation)
    code = (
        "from gymfg_il.sim.simulation import Simulation; from gymfg_il.sim.trim import trim_for;"
        "print(repr(trim_for('c172p', 5250.0, 104.0, 120, Simulation).values()))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == repr(here.values())


def test_low_starts_trim_without_a_grid_point_at_sea_level():
    sim = Simulation("c172p")
    sim.reset(InitialConditions(altitude_ft=600.0, airspeed_kts=100.0, trimmed=True), 0.75)
    assert sim.trim is not None and _hands_off(sim, 3.0)[0] < 50.0


def test_an_aircraft_that_cannot_be_trimmed_names_the_state():
    with pytest.raises(ConfigError, match=r"cannot trim c172p .* 9000 ft and 130 kt"):
        trim_for("c172p", 9000.0, 130.0, 120, Simulation)  # faster than its engine can hold level


def test_near_the_envelope_the_start_itself_is_trimmed():
    # 8,200 ft trims at 110 kt; the grid points above it (9,000 ft) do not
    trim = trim_for("c172p", 8200.0, 110.0, 120, Simulation)
    sim = Simulation("c172p")
    sim.reset(InitialConditions(altitude_ft=8200.0, airspeed_kts=110.0, trimmed=True), 0.75)
    assert sim.trim == trim
    assert _hands_off(sim)[0] < 50.0


def test_untrimmed_starts_remain_a_setting_and_old_records_replay_untrimmed():
    from gymfg_il.envs import AircraftEnv, FlightSpec

    spec = FlightSpec.solo("c172p", "altitude")
    assert spec.trimmed_starts and FlightSpec.from_json(spec.to_json()) == spec
    old = spec.to_dict()
    del old["trimmed_starts"]  # a record written before trimmed starts existed
    assert not FlightSpec.from_dict(old).trimmed_starts
    alphas = {}
    for trimmed in (True, False):
        env = AircraftEnv.from_flight(spec.replace(trimmed_starts=trimmed))
        env.reset(seed=3)
        sim = env.world.slots[0].sim
        alphas[trimmed] = sim.fdm["aero/alpha-deg"]
        assert (sim.trim is not None) == trimmed
        assert env.world.slots[0].action[3] == pytest.approx(sim.start_action[3])
        env.close()
    assert alphas[True] > 0.3 and alphas[False] == pytest.approx(0.0, abs=1e-6)
