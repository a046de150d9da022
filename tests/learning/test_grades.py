"""Training on what is good: ``--select grade=...`` keeps that grade and better ones, and
``--weight grade`` draws each episode's samples in proportion to its grade's weight."""

import dataclasses
from collections import Counter

import pytest

from gymfg_il import train
from gymfg_il.errors import ConfigError
from gymfg_il.learning.batches import TensorBatches
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import GRADE_WEIGHTS, TrainConfig
from gymfg_il.learning.data import grade_weights, load_frames, selected

GRADED = ["excellent", "good", "fair", "unsatisfactory", "good", "fair"]


@pytest.fixture
def graded(tiny_dataset):
    """The tiny dataset's six episodes, graded as ``GRADED`` says."""
    frames = load_frames(tiny_dataset)
    return dataclasses.replace(frames, episodes={**frames.episodes, "gymfg/grade": GRADED})


def test_select_by_grade_keeps_that_grade_and_better(graded):
    assert set(selected(graded, ["grade=excellent"], "here").episode) == {0}
    assert set(selected(graded, ["grade=good"], "here").episode) == {0, 1, 4}
    assert set(selected(graded, ["grade=fair"], "here").episode) == {0, 1, 2, 4, 5}
    with pytest.raises(ConfigError, match="grade= takes excellent or good or fair"):
        TrainConfig(select=["grade=great"])


def test_weighting_draws_each_episode_in_proportion_to_its_grade(graded):
    weights = grade_weights(graded, "here")
    assert [weights[graded.episode == e][0] for e in range(6)] == [4.0, 3.0, 2.0, 1.0, 3.0, 2.0]
    batches = TensorBatches(graded, 256, seed=3, weights=weights)
    drawn = Counter()
    for _ in range(20):  # 20 epochs: about 36,000 draws
        for starts in batches.order().split(256):
            drawn.update(graded.episode[starts.numpy()].tolist())
    total = sum(drawn.values())
    assert total == 20 * len(graded)  # an epoch draws as many samples as there are
    frames = Counter(graded.episode.tolist())
    share = {e: frames[e] * GRADE_WEIGHTS[g] for e, g in enumerate(GRADED)}
    for e in range(6):  # within 5 % of its expected share
        expected = share[e] / sum(share.values())
        assert drawn[e] / total == pytest.approx(expected, rel=0.05), e


def test_weighting_needs_every_episode_graded(graded, tiny_dataset, tmp_path, capsys):
    ungraded = dataclasses.replace(
        graded, episodes={**graded.episodes, "gymfg/grade": [*GRADED[:5], ""]}
    )
    with pytest.raises(ConfigError, match=r"not every episode records a grade.*--weight"):
        grade_weights(ungraded, "an autopilot's dataset")
    with pytest.raises(ConfigError, match="weight='size': want grade"):
        TrainConfig(weight="size")
    # the autopilot's episodes are not graded: the command says so and trains nothing
    argv = ["bc", "--dataset", str(tiny_dataset), "--weight", "grade", "--epochs", "1"]
    assert train.main([*argv, "--out", str(tmp_path / "p"), "--no-progress"]) == 2
    assert "not every episode records a grade" in capsys.readouterr().err
    assert not (tmp_path / "p").exists()


def test_a_weighted_run_trains_and_records_its_weighting(graded, tmp_path):
    cfg = TrainConfig(dataset=tmp_path, out=tmp_path / "p", epochs=2, weight="grade")
    result = train_bc(cfg, frames=graded)
    assert result.train_loss[-1] < result.train_loss[0]
    assert result.meta["train"]["weight"] == "grade"
