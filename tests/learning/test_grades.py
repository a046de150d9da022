"""Training on what is good: ``--select grade=...`` keeps that grade and better ones,
``--weight grade`` draws each episode's samples in proportion to its grade's weight, and a
pilot's frames before the first input are left out."""

import dataclasses
from collections import Counter

import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.learning.batches import TensorBatches
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import GRADE_WEIGHTS, TrainConfig
from gymfg_il.learning.data import load_frames
from gymfg_il.learning.selection import grade_weights, selected

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


def test_weighting_needs_every_episode_graded(graded, tmp_path):
    ungraded = dataclasses.replace(
        graded, episodes={**graded.episodes, "gymfg/grade": [*GRADED[:5], ""]}
    )
    with pytest.raises(ConfigError, match=r"not every episode records a grade.*--weight"):
        grade_weights(ungraded, "a team's dataset")
    with pytest.raises(ConfigError, match="weight='size': want grade"):
        TrainConfig(weight="size")
    cfg = TrainConfig(dataset=tmp_path, out=tmp_path / "p", epochs=1, weight="grade")
    with pytest.raises(ConfigError, match="not every episode records a grade"):
        train_bc(cfg, frames=ungraded)
    assert not (tmp_path / "p").exists()  # refused before anything was trained or written


def test_the_autopilots_episodes_are_graded(tiny_dataset):
    grades = load_frames(tiny_dataset).episodes["gymfg/grade"]
    assert len(grades) == 6 and set(grades) <= {"excellent", "good", "fair", "unsatisfactory"}


def test_a_weighted_run_trains_and_records_its_weighting(graded, tmp_path):
    cfg = TrainConfig(dataset=tmp_path, out=tmp_path / "p", epochs=2, weight="grade")
    result = train_bc(cfg, frames=graded)
    assert result.train_loss[-1] < result.train_loss[0]
    assert result.meta["train"]["weight"] == "grade"


def test_a_pilots_frames_before_the_first_input_are_left_out_unless_asked(tiny_dataset):
    from gymfg_il.learning.bc import demonstrations

    frames = load_frames(tiny_dataset)
    n = len(frames.episodes["gymfg/source"])
    person = dataclasses.replace(
        frames, episodes={**frames.episodes, "gymfg/source": ["human"] * n}
    )
    for e in range(n):  # the first input: frame 1, and in episode 2 frame 10
        at = np.flatnonzero(person.episode == e)
        rest = 10 if e == 2 else 1
        person.action[at[:rest]] = person.action[at[0]]
        person.action[at[rest]] = person.action[at[0]] + 0.01
    cfg = TrainConfig(dataset=tiny_dataset)
    flown = demonstrations(cfg, person, None)
    assert len(flown) == len(person) - (n - 1) - 10
    assert flown.frame[flown.episode == 2][0] == 10 and flown.frame[flown.episode == 0][0] == 1
    asked = demonstrations(dataclasses.replace(cfg, before_first_input=True), person, None)
    assert len(asked) == len(person)
    # another source's episodes are kept whole
    assert len(demonstrations(cfg, frames, None)) == len(frames)
