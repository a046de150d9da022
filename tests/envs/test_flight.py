"""The flight spec: one record of what is flown, read back whole."""

from dataclasses import asdict

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.envs import AircraftEnv, FlightSpec, OfflineEnv
from gymfg_il.envs.scenarios import formation
from gymfg_il.errors import ConfigError, DuplicateNameError, RateError, UnknownAircraftError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks import DummyTask, ReachStaticTargetAltitudeTask, ReachStaticTargetRollTask


def test_a_solo_spec_round_trips_and_builds_its_env():
    options = {"dynamic": True, "task_kwargs": {"hold_s": 12.5}, "agent_hz": 30}
    spec = FlightSpec.solo("a320", "heading", episode_time_s=20, **options)
    assert spec.aircraft == "A320" and spec.task_label == "heading-dynamic"
    assert FlightSpec.from_dict(spec.to_dict()) == spec
    assert FlightSpec.from_json(spec.to_json()) == spec
    env = spec.make_env()
    try:
        assert env.flight == spec and env.dt == pytest.approx(1 / 30)
        assert env.task.hold_s == 12.5 and env.world.max_steps == 600
    finally:
        env.close()


def test_an_env_built_from_its_spec_flies_the_same_episode():
    a = AircraftEnv("roll", "f15", task_kwargs={"target_range": (-10, 10)}, episode_time_s=5)
    b = AircraftEnv.from_flight(FlightSpec.from_json(a.flight.to_json()))
    for env in (a, b):
        env.reset(seed=3)
    action = np.array([0.1, -0.05, 0.0, 0.8])
    for _ in range(20):
        oa, *_ = a.step(action)
        ob, *_ = b.step(action)
        assert np.array_equal(oa, ob)
    a.close()
    b.close()


@pytest.mark.parametrize(
    "make, error, match",
    [
        (lambda: FlightSpec.solo("c172q"), UnknownAircraftError, "c172p"),
        (lambda: FlightSpec.solo(task="altitud"), ConfigError, "unknown task"),
        (lambda: FlightSpec.solo(agent_hz=7), RateError, "agent_hz=7"),
        (lambda: FlightSpec.solo(episode_time_s=0.05), RateError, "whole number"),
        (lambda: FlightSpec.solo(task_kwargs={"target_range": (5, 1)}), ConfigError, "low <= high"),
        (lambda: FlightSpec.solo(task="level", dynamic=True), ConfigError, "no dynamic"),
        (lambda: FlightSpec.from_dict({"teams": [], "colour": 1}), ConfigError, "unknown keys"),
        (lambda: FlightSpec.from_dict({"teams": [], "version": 9}), ConfigError, "version 9"),
        (lambda: FlightSpec.from_dict({"agent_hz": 10}), ConfigError, "no 'teams'"),
        (lambda: FlightSpec.from_json("{not json"), ConfigError, "not valid JSON"),
    ],
)
def test_bad_specs_say_what_is_wrong(make, error, match):
    with pytest.raises(error, match=match):
        make()


def test_a_team_spec_knows_it_is_not_solo_and_refuses_duplicates():
    spec = FlightSpec.of_world(_world_env().world)
    assert not spec.is_solo
    with pytest.raises(ConfigError, match="one aircraft chosen"):
        _ = spec.aircraft
    teams = spec.to_dict()["teams"]
    teams[1]["roster"][0]["callsign"] = teams[0]["roster"][0]["callsign"]
    with pytest.raises(ConfigError, match="appear twice"):
        FlightSpec.from_dict({**spec.to_dict(), "teams": teams})
    solo = spec.for_callsign("blue-1")
    assert solo.is_solo and solo.aircraft == "f15" and solo.task == "roll"
    assert DuplicateNameError  # names the error family a duplicate team raises at run time


# the F-15 flies in the c172p's formation at 110 kt, far below any speed JSBSim can trim it at:
# an untrimmed start, on purpose
_LEAD = InitialConditions(altitude_ft=5000, airspeed_kts=110, trimmed=False)


def _world_env():
    red = Team(
        "red",
        [
            (c172p("red-1"), ReachStaticTargetAltitudeTask),
            (c172p("red-2"), lambda: ReachStaticTargetAltitudeTask(target_range=(-200, 200))),
        ],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=10,
    )
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetRollTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent()])], scenario=formation(_LEAD, 500))
    env.reset(red, seed=1)
    return env


def test_the_spec_of_a_team_world_rebuilds_that_world():
    env = _world_env()
    spec = FlightSpec.of_world(env.world)
    assert spec.rebuild_problems() == []
    assert spec.scenario == {
        "name": "formation",
        "lead": asdict(_LEAD),
        "spacing_ft": 500.0,
        "jitter_ft": 0.0,
        "heading_jitter_deg": 0.0,
    }
    again = FlightSpec.from_json(spec.to_json())
    assert again == spec and again.episode_time_s == 10
    world = again.make_world()
    for w in (world, env.world):
        w.reset(np.random.default_rng(5))
        w.advance([(0.0, -0.02, 0.0, 0.7)] * 3)
    for mine, theirs in zip(world.slots, env.world.slots, strict=True):
        assert mine.callsign == theirs.callsign
        assert mine.task.observation_names == theirs.task.observation_names
        assert np.array_equal(mine.state, theirs.state)  # placed alike by the scenario
    assert world.by_callsign["red-2"].task.target_range == (-200, 200)
    world.close()
    env.close()


def test_what_a_record_cannot_rebuild_is_named():
    lead = InitialConditions(altitude_ft=4000)
    team = Team("ego", [(c172p("ego"), DummyTask(reward=lambda ctx: 1.0, start=lead))])
    env = OfflineEnv()
    env.reset(team, seed=0)
    spec = FlightSpec.of_world(env.world)
    problems = spec.rebuild_problems()
    assert len(problems) == 1 and "python:" in problems[0] and "<lambda>" in problems[0]
    assert spec.teams[0].roster[0].task_kwargs["start"]["initial_conditions"]["altitude_ft"] == 4000
    with pytest.raises(ConfigError, match="cannot rebuild"):
        spec.build_teams()
    env.close()


class StopAfter(DummyTask):
    """A task of one's own with an argument of its own."""

    def __init__(self, stop_after: int, **kwargs):
        super().__init__(**kwargs)
        self.stop_after = stop_after


def test_a_tasks_own_arguments_are_recorded_whatever_its_signature():
    import functools

    for build in (lambda: StopAfter(15), functools.partial(StopAfter, stop_after=15)):
        team = Team("ego", [(c172p("ego"), build)])
        env = OfflineEnv()
        env.reset(team, seed=0)
        spec = FlightSpec.of_world(env.world)
        (ego,) = spec.aircraft_specs
        assert ego.task.endswith(":StopAfter") and dict(ego.task_kwargs) == {"stop_after": 15}
        env.close()


def test_specs_are_immutable_hashable_and_check_their_parts():
    spec = FlightSpec.solo(task_kwargs={"target_range": [-100, 100]})
    again = FlightSpec.from_json(spec.to_json())
    assert again == spec and hash(again) == hash(spec) and len({spec, again}) == 1
    with pytest.raises(TypeError, match=r"FlightSpec\.replace"):
        spec.task_kwargs["target_range"] = (0, 1)
    assert spec.replace(task_kwargs={"target_range": (0, 1)}).task_kwargs["target_range"] == (0, 1)
    record = spec.to_dict()
    record["teams"][0]["reward_targets"] = {"nobody": [{"callsign": "ego", "model": "c172p"}]}
    with pytest.raises(ConfigError, match="not in its roster"):
        FlightSpec.from_dict(record)
    with pytest.raises(ConfigError, match="twice"):
        FlightSpec.solo().replace(opponent_view=("lat_deg", "lat_deg"))
    for bad in ({**spec.to_dict(), "agent_hz": "10"}, {**spec.to_dict(), "episode_time_s": None}):
        with pytest.raises(ConfigError):
            FlightSpec.from_dict(bad)
    odd = spec.replace(scenario={"name": "barrel_roll"})
    assert "barrel_roll" in odd.rebuild_problems()[0]
    lead = formation(lead=InitialConditions(altitude_ft=3000), spacing_ft=100)
    from gymfg_il.envs.scenarios import scenario_record

    placed = spec.replace(scenario=scenario_record(lead))
    back = FlightSpec.from_json(placed.to_json())
    assert back == placed and back.env_config().scenario == lead


def test_a_record_may_not_make_gymfg_import_the_task_it_names(tmp_path, monkeypatch):
    """A dataset, log or checkpoint names its task; an import path whose module nobody
    imported is refused before anything is imported (red team #32.1: files never run code)."""
    from gymfg_il.errors import UntrustedTaskError

    marker = tmp_path / "ran"
    (tmp_path / "evil_task_module.py").write_text(
        f"open({str(marker)!r}, 'w').write('ran')\nfrom gymfg_il.tasks import DummyTask as Task\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    record = FlightSpec.solo("c172p", "altitude").to_dict()
    record["teams"][0]["roster"][0]["task"] = "evil_task_module:Task"
    with pytest.raises(UntrustedTaskError, match=r"evil_task_module.*not imported"):
        FlightSpec.from_dict(record)
    assert not marker.exists()
    # the user's trust, given by name, lets it be built
    monkeypatch.setenv("GYMFG_TASK_MODULES", "other, evil_task_module")
    spec = FlightSpec.from_dict(record)
    assert not marker.exists()  # reading the record still imports nothing
    spec.solo_aircraft.task_factory()()
    assert marker.read_text() == "ran"


@pytest.mark.parametrize("name", ["red\nteam", "\x1b[2J", "a\x00", "\u202eder", "x" * 65, ""])
def test_a_spec_refuses_names_that_are_not_printable(name):
    from gymfg_il.envs.flight import AircraftSpec, TeamSpec

    with pytest.raises(ConfigError, match="printable"):
        TeamSpec(name, (AircraftSpec(),))
    with pytest.raises(ConfigError, match="printable"):
        AircraftSpec(callsign=name)
