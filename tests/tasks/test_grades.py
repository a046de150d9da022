"""Grades: the four words from a task's measured errors (``tasks.grades``), each task's
measures from its own judge, and the briefing that says how a flight is graded."""

import numpy as np
import pytest

from gymfg_il.display.briefing import briefing, debrief
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.seeded import fly_many
from gymfg_il.sim.properties import INDEX, NAMES
from gymfg_il.tasks.grades import GRADES, Measure, grade, rank
from gymfg_il.tasks.maneuvers import TurnTask


def measure(share):
    return Measure("altitude", "ft", share * 100.0, 100.0)


@pytest.mark.parametrize(
    ("shares", "expected"),
    [
        ([0.1, 0.25], "excellent"),
        ([0.1, 0.26], "good"),
        ([0.5], "good"),
        ([0.2, 0.51], "fair"),
        ([0.9], "fair"),
        ([], "excellent"),  # nothing measured: flown to the end is all it asks
    ],
)
def test_a_success_is_graded_by_its_largest_share_of_a_tolerance(shares, expected):
    assert grade(True, [measure(s) for s in shares]) == expected


def test_a_failure_is_unsatisfactory_and_an_unmeasured_span_is_fair():
    assert grade(False, [measure(0.01)]) == "unsatisfactory"
    assert grade(True, [Measure.of("heading", "deg", [], 5.0)]) == "fair"  # NaN: no span
    assert [rank(g) for g in GRADES] == [0, 1, 2, 3]
    assert rank("") == rank("superb") == rank(None) == -1  # as a hostile log may hold


def test_a_measure_is_the_worst_error_or_the_mean_where_the_rule_averages():
    m = Measure.of("glide path", "ft", [30.0, -40.0, 10.0], 100.0)
    assert (m.value, m.share, m.kind) == (40.0, 0.4, "worst")
    gusty = Measure.of("altitude", "ft", [30.0, -40.0, 20.0], 50.0, mean=True)
    assert (gusty.value, gusty.kind) == (30.0, "mean")


def test_the_turns_judge_measures_what_its_success_rule_bounds():
    n, dt = 900, 0.1
    states = np.zeros((n, len(NAMES)))
    states[:, INDEX["heading_deg"]] = np.minimum(np.arange(n) * 0.5, 90.0)
    states[:, INDEX["altitude_ft"]] = 5000.0 + 40.0 * np.sin(np.arange(n) / 50.0)
    plan = {"turn_deg": 90.0, "start_heading_deg": 0.0, "altitude_ft": 5000.0}
    verdict = TurnTask.judge(plan, states, dt)
    assert verdict.success
    altitude, heading = verdict.measures
    worst = np.abs(40.0 * np.sin(np.arange(n) / 50.0)).max()
    assert (altitude.tolerance, altitude.value) == (100.0, pytest.approx(worst))
    assert (heading.tolerance, heading.value) == (5.0, 0.0)
    assert verdict.grade == "good"  # the altitude's worst used 40 % of its tolerance


@pytest.mark.parametrize("task", ["turn", "approach", "formation"])
def test_an_experts_success_is_graded_from_its_measures(task):
    flight = FlightSpec.solo("c172p", task)
    (ep,) = fly_many(flight, AgentSpec.controller(), [4401])
    t = ep.solo
    env = flight.make_env()
    env.reset(seed=4401)  # the same plan as flown
    states = np.vstack([t.start.state[None], t.states])
    errors = np.zeros(len(t.states))  # a maneuver's judge reads the states alone
    judged = debrief(env.world.slots[0].task, states, errors, ep.dt, "time limit", 0.0)
    assert judged.success and judged.grade in ("excellent", "good")
    assert f"grade: {judged.grade} (" in " ".join(judged.lines)


def test_the_briefing_says_how_each_task_is_graded():
    env = FlightSpec.solo("c172p", "approach").make_env()
    lines = " ".join(briefing(env.world.slots[0].task, 180.0))
    success = lines[lines.index("Success:") : lines.index("Grade:")]
    assert "localizer" in lines and "Excellent when the worst of each stays within 25%" in lines
    assert "Grade" not in success[1:]  # the success sentence stops where the grade begins
    env = FlightSpec.solo("c172p", "altitude").make_env()
    assert "Grade: the error over the last 10 s" in " ".join(briefing(env.world.slots[0].task, 90))


def test_the_approach_grades_the_bank_on_final_but_does_not_fail_it():
    from gymfg_il.tasks.approach import ApproachTask

    flight = FlightSpec.solo("c172p", "approach")
    (ep,) = fly_many(flight, AgentSpec.controller(), [4402])
    env = flight.make_env()
    env.reset(seed=4402)
    plan = env.world.slots[0].task.plan
    states = np.vstack([ep.solo.start.state[None], ep.solo.states])
    flown = ApproachTask.judge(plan, states, ep.dt)
    bank = flown.measures[-1]
    assert (bank.name, bank.tolerance) == ("bank", 15.0) and bank.value < 3.75
    # a wing down 10 deg all the way down the final: two thirds of the bank a stabilized
    # final allows, fair; the needles are untouched, so still a success
    final = ApproachTask.geometry(plan, states)["distance"] <= plan["hold_from_ft"]
    states[final, INDEX["roll_deg"]] = 10.0
    banked = ApproachTask.judge(plan, states, ep.dt)
    assert banked.success and banked.measures[:3] == flown.measures[:3]
    assert banked.measures[-1].value == 10.0 and banked.grade == "fair"
    # in turbulence the bank grades by its mean over the final, as the other measures do
    gusty = ApproachTask.judge(plan, states, ep.dt, gusty=True).measures[-1]
    assert (gusty.kind, gusty.value) == ("mean", 10.0)
