import math

import numpy as np
import pytest

from gymfg_il.evaluation.metrics import score_episode, summarize
from gymfg_il.evaluation.trace import Trace


def episode(error, dynamic=False, terminated=False, tolerance=1.0):
    error = np.asarray(error, dtype=float)
    n = len(error)
    actions = np.zeros((n, 4))
    actions[:, 1] = np.linspace(0, 0.1, n)
    return Trace(
        seed=3,
        variable="roll_deg",
        tolerance=tolerance,
        dynamic=dynamic,
        dt=0.1,
        target=np.full(n, 30.0),
        value=30.0 - error,
        error=error,
        actions=actions,
        rewards=np.ones(n),
        terminated=terminated,
        reason=None,
    )


def test_reaching_and_holding_is_success():
    err = np.concatenate([np.linspace(30, 0, 50), np.full(150, -2.0), np.zeros(200)])
    s = score_episode(episode(err), hold_s=10)
    assert s.success and s.steady_state_error == 0
    assert s.time_to_target_s == pytest.approx((np.flatnonzero(np.abs(err) <= 1)[0] + 1) * 0.1)
    assert s.overshoot == pytest.approx(2.0)
    assert s.control_effort == pytest.approx(0.05 / 3, rel=1e-6)
    assert s.smoothness == pytest.approx(0.1 / 399 / 3, rel=1e-6)


def test_drifting_off_or_crashing_is_not_success():
    err = np.concatenate([np.zeros(300), np.linspace(0, 5, 100)])
    assert not score_episode(episode(err)).success
    assert not score_episode(episode(np.zeros(400), terminated=True)).success
    assert math.isnan(score_episode(episode(np.full(400, 9.0))).time_to_target_s)


def test_dynamic_targets_get_a_tracking_tolerance():
    assert score_episode(episode(np.full(400, 2.5), dynamic=True)).success
    assert not score_episode(episode(np.full(400, 2.5))).success


def test_summary_row_has_the_json_schema():
    row = summarize("controller", "roll", "c172p", [episode(np.zeros(400)), episode(np.ones(400))])
    for key in (
        "agent",
        "task",
        "aircraft",
        "episodes",
        "seeds",
        "mean_return",
        "std_return",
        "success_rate",
        "time_to_target_s",
        "steady_state_error",
    ):
        assert key in row
    assert row["episodes"] == 2 and row["success_rate"] == 1.0 and row["mean_return"] == 400
