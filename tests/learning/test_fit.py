"""The run's estimate and loss curve: timing a few batches before training changes nothing
the run learns, and the curve counts whole epochs and names the loss it shows."""

from pathlib import Path

import numpy as np
import pytest

from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.saving import loss_figure
from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.configuration_vision import VisionConfig
from gymfg_il.policies.modeling_vision import VisionPolicy

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"


def test_the_estimate_before_training_changes_nothing_it_learns(tmp_path):
    def run(out, on_start=None):
        cfg = TrainConfig(
            dataset=SAMPLE,
            out=out,
            policy=GRUConfig(hidden=8, sequence_length=4),
            epochs=2,
            obs_noise=0.1,  # draws from torch's generator every batch
        )
        return train_bc(cfg, on_start=on_start)

    estimates = []
    timed = run(tmp_path / "timed", estimates.append)
    plain = run(tmp_path / "plain")
    assert timed.train_loss == plain.train_loss and timed.val_loss == plain.val_loss
    weights = [(r.out / "model.safetensors").read_bytes() for r in (timed, plain)]
    assert weights[0] == weights[1]
    (estimate,) = estimates
    assert estimate.epochs == 2 and estimate.batches == 64 and estimate.val_batches == 2
    assert estimate.seconds == pytest.approx(2 * (64 * estimate.batch_s + 2 * estimate.val_batch_s))
    assert estimate.batch_s > 0 and estimate.val_batch_s > 0


def test_the_loss_curve_counts_whole_epochs_and_says_what_the_loss_is():
    fig = loss_figure([1.0, 0.5, 0.25], [1.2, 0.6, 0.4], "three epochs", "MSE (normalised)")
    ax = fig.axes[0]
    low, high = ax.get_xlim()
    ticks = [t for t in ax.get_xticks() if low <= t <= high]
    assert ticks and all(float(t).is_integer() for t in ticks)
    assert ax.get_ylabel() == "MSE (normalised)"


def test_a_vision_policys_loss_names_the_eyes_term():
    names = ["roll_deg", "roll_deg_target", "roll_deg_error"]
    cfg = VisionConfig.for_observation(names, image_size=16, pool=1, channels=[4], hidden=[8])
    unit = {"mean": np.zeros(3), "std": np.ones(3)}
    policy = VisionPolicy(cfg, unit, {"mean": np.zeros(4), "std": np.ones(4)})
    assert policy.loss_label == "action MSE + 1 x eye MSE (normalised)"
