"""Episode metadata after LeRobot's own dataset editing: `collect repair` takes each edited
episode's gymfg/* columns from the dataset(s) it came from, found by its frames."""

from __future__ import annotations

import pytest

from gymfg_il import collect
from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.provenance import metadata_columns


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("provenance")
    for name, seed in (("a", "1000"), ("b", "3000")):
        argv = ["autopilot", "--task", "roll", "--episodes", "3", "--episode-time", "5"]
        assert collect.main([*argv, "--seed", seed, "--out", str(tmp / name), "--no-progress"]) == 0
    return tmp


@pytest.mark.slow
def test_split_episodes_get_their_own_metadata_back(sessions, capsys):
    from lerobot.datasets.dataset_tools import split_dataset

    source = lr.open_dataset(sessions / "a/dataset")
    parts = split_dataset(source, splits={"train": [0, 2], "val": [1]}, output_dir=sessions / "s")
    train = parts["train"].root
    assert metadata_columns(lr.open_metadata(train)) == {}  # LeRobot's split drops them
    wrong = ["repair", str(train), "--source", str(sessions / "b")]
    assert collect.main(wrong) == 2
    assert "2 of the 2 episodes" in capsys.readouterr().err
    for part, seeds in ((train, [1000, 1002]), (parts["val"].root, [1001])):
        argv = [
            "repair",
            str(part),
            "--source",
            str(sessions / "b"),
            "--source",
            str(sessions / "a"),
        ]
        assert collect.main(argv) == 0
        assert metadata_columns(lr.open_metadata(part))["gymfg/seed"] == seeds


def test_lerobots_merge_keeps_the_columns(sessions):
    from lerobot.datasets.dataset_tools import merge_datasets

    a, b = (lr.open_dataset(sessions / n / "dataset") for n in "ab")
    merged = merge_datasets([a, b], output_repo_id="gymfg/merged", output_dir=sessions / "m")
    seeds = metadata_columns(lr.open_metadata(merged.root))["gymfg/seed"]
    assert seeds == [1000, 1001, 1002, 3000, 3001, 3002]
