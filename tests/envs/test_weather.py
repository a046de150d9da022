"""Turbulence and wind: JSBSim's own models, seeded per episode, recorded in the spec."""

import numpy as np
import pytest

from gymfg_il.envs import AircraftEnv, FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.sim.weather import Weather


def flown(env, seed, steps=60):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for _ in range(steps):
        obs, *_ = env.step(np.array([0.0, -0.02, 0.0, 0.75]))
        out.append(obs)
    return np.array(out)


def test_turbulence_with_the_same_seed_reproduces_bit_for_bit(make_env):
    env = make_env("altitude", turbulence="moderate", wind_kt=15.0)
    again = make_env("altitude", turbulence="moderate", wind_kt=15.0)
    a, b = flown(env, 3), flown(again, 3)
    assert np.array_equal(a, b)  # a fresh env and seed: the same gusts
    assert np.array_equal(flown(env, 3), a)  # a reused one: the same gusts again
    assert not np.array_equal(flown(env, 4), a)  # another seed: other gusts
    calm = flown(make_env("altitude"), 3)
    q = 6  # observation index of the pitch rate: gusts shake it from step to step
    gusts = np.abs(np.diff(a[20:, q])).mean()  # after the start transient
    assert gusts > 3 * np.abs(np.diff(calm[20:, q])).mean()


def test_calm_air_is_the_air_every_earlier_episode_was_flown_in(make_env):
    default = flown(make_env("roll"), 9)
    calm = flown(make_env("roll", turbulence="none", wind_kt=0.0), 9)
    assert np.array_equal(default, calm)


def test_a_steady_wind_moves_the_aircraft_over_the_ground(make_env):
    env = make_env("level", wind_kt=30.0)
    env.reset(seed=1)
    for _ in range(40):
        env.step(np.array([0.0, -0.02, 0.0, 0.75]))
    drifted = env.world.slots[0].state[:2].copy()
    calm = make_env("level")
    calm.reset(seed=1)
    for _ in range(40):
        calm.step(np.array([0.0, -0.02, 0.0, 0.75]))
    metres = np.abs(drifted - calm.world.slots[0].state[:2]).max() * 111_000.0  # lat/lon degrees
    seconds = 40 / env.flight.agent_hz
    assert metres > 0.5 * 30.0 * 0.5144 * seconds  # at least half the wind's drift, 30 kt in m/s


def test_the_weather_is_part_of_the_flight_spec():
    spec = FlightSpec.solo(task="roll", turbulence="light", wind_kt=10.0, wind_from_deg=270.0)
    back = FlightSpec.from_json(spec.to_json())
    assert back == spec and back.weather == Weather("light", 10.0, 270.0)
    assert AircraftEnv.from_flight(spec).flight == spec
    for bad in ({"turbulence": "hurricane"}, {"wind_kt": -3.0}):
        with pytest.raises(ConfigError, match="weather"):
            FlightSpec.solo(**bad)


def test_a_flight_says_whether_it_is_gusty():
    """#53: one rule (``Weather.gusty``) for whether a verdict allows for gusts."""
    assert FlightSpec.solo(task="roll", turbulence="light").gusty
    assert not FlightSpec.solo(task="roll", wind_kt=10.0).gusty  # a steady wind is no gust
    assert not FlightSpec.solo(task="roll").weather.gusty and Weather().calm


def test_controllers_hold_their_targets_in_moderate_turbulence():
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.runner import run_eval

    for task in ("altitude", "roll"):
        run = run_eval(EvalConfig(task=task, episodes=4, turbulence="moderate", workers=2))
        (row,) = run.rows
        assert row["success_rate"] >= 0.75 and row["terminated"] == 0
        assert row["spec"]["turbulence"] == "moderate"


def test_demonstrations_can_be_collected_in_turbulence_and_keep_it_in_their_spec(tmp_path):
    from gymfg_il import collect
    from gymfg_il.learning.data import load_frames

    weather = ["--turbulence", "light", "--wind-kt", "5"]
    argv = ["autopilot", "--task", "roll", "--episodes", "1", "--episode-time", "3", *weather]
    assert collect.main([*argv, "--out", str(tmp_path), "--no-progress"]) == 0
    flight, why = load_frames(tmp_path / "dataset").flight()
    assert flight is not None, why
    assert flight.weather.turbulence == "light" and flight.weather.wind_kt == 5.0
