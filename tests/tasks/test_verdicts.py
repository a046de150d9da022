"""One accumulator judges every episode (``tasks.verdicts.EpisodeVerdict``): step by step or
from a flown episode, the same verdict; every caller (the cockpit's debrief, the collector's
end record, PPO's success bonus, eval's trace) gives it for the same flight."""

import warnings

import numpy as np
import pytest

from gymfg_il.collectors.session import judged
from gymfg_il.display.briefing import debrief_of
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.evaluation.metrics import score_episode
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.rl.reward import SuccessBonus
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.tasks.maneuvers import TurnTask
from gymfg_il.tasks.verdicts import EpisodeVerdict, TrackedError, judge_flight


def flown(task, seed, aircraft="c172p", episode_time_s=30.0, **options):
    """(env, episode, the verdict accumulated step by step as the cockpit's recorder does)."""
    flight = FlightSpec.solo(aircraft, task, episode_time_s=episode_time_s, **options)
    env = flight.make_env()
    episode = Rollout(env, [AgentSpec.controller().make(env)]).episode(seed=seed)
    t = episode.solo
    env.reset(seed=seed)  # the same plan as flown
    verdict = EpisodeVerdict.of(env.task, env.dt, flight.gusty)
    verdict.start(t.start.state)
    for state, observation in zip(t.states, t.next_observations, strict=True):
        verdict.add(state, observation)
    return env, episode, verdict


@pytest.mark.parametrize(("task", "turbulence"), [("altitude", "none"), ("turn", "light")])
def test_step_by_step_and_all_at_once_give_one_verdict(task, turbulence):
    env, episode, verdict = flown(task, 61, turbulence=turbulence)
    assert env.flight.gusty == verdict.gusty == (turbulence == "light")
    t = episode.solo
    states = np.vstack([t.start.state[None], t.states])
    at_once = EpisodeVerdict.flown(
        t.start.task,
        states,
        verdict.tracked.column(t.next_observations),
        episode.dt,
        env.flight.gusty,
    )
    assert np.array_equal(at_once.states, verdict.states) and verdict.steps == len(t.states)
    assert np.allclose(at_once.errors, verdict.errors)
    assert at_once.judge() == verdict.judge() is not None
    crashed = verdict.judge("crashed")
    assert (crashed.success, crashed.detail, crashed.measures) == (False, "crashed", ())


def test_every_caller_gives_the_verdict_of_the_one_accumulator():
    env, episode, verdict = flown("turn", 62, episode_time_s=90.0)
    found = verdict.judge()
    assert found is not None and found.success
    end = judged(episode, gusty=False)
    assert end == {"success": True, "verdict": found.detail, "grade": found.grade}
    said = debrief_of(verdict, "time limit", 0.0)
    assert (said.success, said.detail, said.grade) == (True, found.detail, found.grade)
    trace = trace_of(episode)
    assert (trace.verdict, trace.detail, score_episode(trace).success) == (True, found.detail, True)
    bonus = SuccessBonus(env, 0.01)
    bonus.reset(seed=62)
    for action in episode.solo.actions:
        *_, truncated, info = bonus.step(action)
    assert truncated and info["is_success"] is True


def test_a_terminated_episode_fails_whatever_it_flew():
    _, _, verdict = flown("altitude", 63, episode_time_s=90.0)
    assert verdict.judge().success
    crashed = verdict.judge("crashed")
    assert (crashed.success, crashed.detail, crashed.grade) == (False, "crashed", "unsatisfactory")


def test_a_target_is_held_on_its_mean_in_turbulence():
    record = {
        "task": "altitude",
        "observation": ["altitude_ft", "altitude_ft_error"],
        "tracked": {
            "variable": "altitude_ft",
            "error": "altitude_ft_error",
            "tolerance": 50.0,
            "dynamic": False,
        },
    }
    errors = np.tile([80.0, -10.0], 100)  # a gust past the tolerance every other step
    states = np.zeros((len(errors) + 1, 3))
    calm = EpisodeVerdict.flown(record, states, errors, 0.1).judge()
    gusty = EpisodeVerdict.flown(record, states, errors, 0.1, gusty=True).judge()
    assert not calm.success and gusty.success and gusty.measures[0].kind == "mean"
    assert TrackedError.of(record) == TrackedError(
        "altitude_ft", "altitude_ft_error", 1, 50.0, False
    )


def test_a_task_without_a_target_is_flown_to_the_end_and_never_gated():
    _, _, verdict = flown("dummy", 64)
    assert verdict.tracked is None and not len(verdict.errors)
    assert verdict.judge().detail == "flown to the end"


def test_a_maneuver_a_record_names_by_path_is_judged_only_by_a_judge_given():
    _, episode, verdict = flown("turn", 65)
    record = {**episode.solo.start.task, "task": "my.tasks:Turn"}  # never imported to judge
    assert EpisodeVerdict.flown(record, verdict.states, [], 0.1).judge() is None
    given = EpisodeVerdict.flown(record, verdict.states, [], 0.1, judge=TurnTask.judge)
    assert given.judge() == verdict.judge()


def test_judge_flight_still_judges_and_says_it_is_deprecated():
    _, _, verdict = flown("altitude", 66)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = judge_flight(verdict.task, verdict.states, verdict.errors, 0.1)
    assert caught[0].category is DeprecationWarning and "EpisodeVerdict" in str(caught[0].message)
    found = verdict.judge()
    assert old == (found.success, found.detail, found.measures)
