"""The flight options are declared once (``FlightOptions``) and everything that flies one
aircraft builds on them; the task names come from one registry."""

import dataclasses

import pytest

from gymfg_il import collect
from gymfg_il import eval as evaluate
from gymfg_il.cli import field_docs
from gymfg_il.collectors.config import CollectConfig, ManualConfig
from gymfg_il.envs import AircraftEnv, FlightSpec
from gymfg_il.envs.options import FlightOptions
from gymfg_il.envs.registration import IDS
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.config import EvalConfig
from gymfg_il.tasks.library import MANEUVERS, TASK_FAMILIES, TRACKED_TASKS
from gymfg_il.tasks.maneuvers import ManeuverTask

OPTIONS = [f.name for f in dataclasses.fields(FlightOptions)]


def test_the_options_build_the_solo_flight_and_read_it_back():
    given = {"aircraft": "f15", "task": "roll", "dynamic": True, "agent_hz": 30}
    given |= {"turbulence": "light", "wind_kt": 5.0, "wind_from_deg": 270.0}
    spec = FlightSpec.solo(**given)
    assert FlightOptions(**given).flight() == spec
    assert FlightOptions.of(spec).flight() == spec
    assert FlightOptions.of(spec).given()["wind_from_deg"] == 270.0
    assert FlightOptions().flight() == FlightSpec.solo() == FlightSpec()
    assert FlightOptions(task="approach").flight().episode_time_s == 180.0  # the task's own
    assert FlightOptions(task="roll", episode_time_s=20).flight().episode_time_s == 20


def test_a_mistyped_option_is_named_with_the_options_there_are():
    for make in (lambda: FlightSpec.solo(agnet_hz=30), lambda: AircraftEnv("roll", agnet_hz=30)):
        with pytest.raises(ConfigError, match=r"unknown flight options \['agnet_hz'\].*agent_hz"):
            make()


def test_the_env_flies_the_flight_its_options_describe():
    env = AircraftEnv("roll", "f15", agent_hz=30, episode_time_s=20, turbulence="light")
    try:
        spec = FlightSpec.solo("f15", "roll", agent_hz=30, episode_time_s=20, turbulence="light")
        assert env.flight == spec and env.metadata["render_fps"] == 30
        assert env.world.max_steps == 600 and env.world.config.weather.turbulence == "light"
        again = AircraftEnv.from_flight(spec)
        assert again.flight == spec
        again.close()
    finally:
        env.close()


def test_every_command_config_builds_on_the_options_and_declares_none_again():
    for cls in (CollectConfig, ManualConfig, EvalConfig):
        assert issubclass(cls, FlightOptions)
        assert not set(OPTIONS) & set(vars(cls).get("__annotations__", {})), cls
        docs = field_docs(cls)  # each option's help comes from FlightOptions' docstring
        assert all(docs[name] == field_docs(FlightOptions)[name] for name in OPTIONS)


def test_the_flags_keep_their_names_and_defaults():
    flight = ("aircraft", "task", "dynamic", "episode_time_s", "agent_hz", "turbulence")
    auto = vars(collect.parse_args(["autopilot"]))
    defaults = ["c172p", "altitude", False, None, 10, "none", 0.0]
    assert [auto[k] for k in (*flight, "wind_kt")] == defaults
    manual = vars(collect.parse_args(["manual", "--fps", "60"]))
    assert (manual["agent_hz"], manual["episodes"]) == (60, 0)
    assert str(manual["out"]) == "datasets/manual"
    assert manual["noise"] == 0.0 and manual["device"] == "keyboard"  # the synthetic pilot's
    assert manual["gusts"] is None and "gusts" not in auto  # a manual session's option
    assert all(vars(evaluate.parse_args([]))[k] is None for k in (*flight, "wind_kt"))
    given = vars(evaluate.parse_args(["--episode-time", "30", "--turbulence", "severe"]))
    assert (given["episode_time_s"], given["turbulence"]) == (30.0, "severe")


def test_task_names_come_from_one_registry():
    assert set(IDS.values()) == set(TASK_FAMILIES) and len(IDS) == len(TASK_FAMILIES)
    names = "Altitude Roll Pitch Heading Airspeed Sideslip LevelFlight Dummy Turn ClimbTurn"
    names += " Waypoints Formation Approach"
    assert sorted(IDS) == sorted(f"GymFG/{name}-v0" for name in names.split())
    maneuvers = [n for n, (cls, _) in TASK_FAMILIES.items() if issubclass(cls, ManeuverTask)]
    assert maneuvers == list(MANEUVERS)
    assert set(TASK_FAMILIES) - set(TRACKED_TASKS) == {"dummy"}
    help_text = field_docs(FlightOptions)["task"]  # --help lists every task a command flies
    assert all(name in help_text for name in TRACKED_TASKS)
