"""The path a new user takes first, with default flags everywhere: collect -> train -> eval.

Autopilot demonstrations flown without noise never leave the expert's path, so a policy cloned
from them meets states it never saw the moment it drifts, and flew the aircraft into the
ground (issue 16: 0-8% success). Collection adds DART noise by default now; these tests fail if
that default goes.
"""

import pytest

from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.evaluation.config import EvalConfig
from gymfg_il.evaluation.runner import run_eval
from gymfg_il.learning.bc import TrainResult, train_bc
from gymfg_il.learning.config import TrainConfig


# altitude needs the 40 demonstrations: from 20, its policy holds the 50-ft tolerance
# in 14 of 16 held-out episodes (a steady offset, no crash)
@pytest.mark.slow
@pytest.mark.parametrize(("task", "demonstrations"), [("roll", 20), ("altitude", 40)])
def test_clean_demonstrations_with_default_settings_give_a_policy_that_does_not_crash(
    task, demonstrations, tmp_path
):
    cfg = CollectConfig(task=task, episodes=demonstrations, seed=1000, out=tmp_path / "demos")
    assert cfg.dart_noise() > 0  # the default that makes the rest hold
    collect_autopilot(cfg, workers=2)
    result = train_bc(TrainConfig(dataset=tmp_path / "demos" / "dataset", out=tmp_path / "p"))
    assert not result.overfit
    run = run_eval(EvalConfig(policy=[tmp_path / "p"], episodes=6, seed=700, workers=2))
    controller, policy = run.rows
    assert policy["terminated"] == 0, policy  # held-out seeds: the demonstrations used 1000+
    assert policy["success_rate"] >= 0.8 * controller["success_rate"]
    assert policy["return_ratio"] >= 0.9


def test_train_says_when_validation_loss_is_far_above_training_loss(tmp_path):
    def result(train, val):
        return TrainResult(tmp_path, [0.5, train], [0.5, val], 1.0, 100, {})

    warning = result(0.0006, 0.0216).overfit  # the memorised roll policy
    assert "36.0x" in warning and "--noise" in warning
    assert "35.6x" in result(0.0008, 0.0285).overfit  # the same from trimmed starts, no noise
    assert result(0.020, 0.021).overfit == ""  # a policy that generalises
    # default noise from trimmed starts: one held-out episode's throttle and elevator follow
    # integrals the task does not observe, yet the policy flew 16 of 16 held-out episodes
    assert result(0.0255, 0.2587).overfit == ""
    assert result(0.0167, 0.3363).overfit == ""  # the same with the trim in the controls: 20x
    assert result(0.0001, 0.0004).overfit == ""  # both tiny: nothing worth a warning
    # every demonstration flown with DART noise: the remedy is there already (roll from 20,
    # with the throttle noised, read 60x and flew every held-out episode)
    noised = TrainResult(tmp_path, [0.5, 0.0544], [0.5, 3.2428], 1.0, 100, {}, noised=True)
    assert noised.overfit == "" and "59.6x" in result(0.0544, 3.2428).overfit


def test_each_task_demonstrates_with_its_own_noise_unless_told(tmp_path):
    from gymfg_il.recording.reader import read_log

    assert CollectConfig(task="altitude").dart_noise() == 0.1
    assert CollectConfig(task="heading").dart_noise() == 0.2  # its slope needs it
    assert CollectConfig(task="heading", dynamic=True).dart_noise() == 0.1
    assert CollectConfig(task="turn").dart_noise() == 0.2
    assert CollectConfig(task="climb-turn").dart_noise() == 0.1
    assert CollectConfig(task="heading", noise=0.0).dart_noise() == 0.0  # asked: kept
    cfg = CollectConfig(task="heading", episodes=1, episode_time_s=2, out=tmp_path / "s")
    collect_autopilot(cfg)
    (log,) = (tmp_path / "s" / "logs").glob("*.mcap")
    assert read_log(log).session["noise"] == 0.2
