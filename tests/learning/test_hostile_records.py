"""`train bc` on datasets whose episode records or files were changed (red team, issue 52):
a record of the wrong kind, a rewritten episode index, a dataset merged with itself, a data
page flipped into other numbers. Each is one line "error: ..." with exit status 2 (or, for
the repeated episodes, a warning and each episode trained once), never a traceback and never
a policy trained on what the records do not say."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gymfg_il import train

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    for needle in needles:
        assert needle in err, err


def copied(tmp_path):
    root = tmp_path / "dataset"
    shutil.copytree(SAMPLE, root)
    return root


def episodes_table(root):
    return next((root / "meta" / "episodes").rglob("*.parquet"))


def set_column(path, name, values, type=None):
    table = pq.read_table(path)
    at = table.schema.get_field_index(name)
    pq.write_table(table.set_column(at, name, pa.array(values, type=type)), path)


def bc(tmp_path, root, *args):
    out = tmp_path / "p"
    argv = ["bc", "--dataset", str(root), "--epochs", "1", "--hidden", "16", "--out", str(out)]
    return train.main([*argv, "--no-progress", *args]), out


@pytest.mark.parametrize("select", ["success", "failure"])
@pytest.mark.parametrize("value", [None, "yes", 1.0, True])
def test_a_verdict_that_is_not_an_integer_is_one_error(tmp_path, capsys, select, value):
    """#52.2: `--select success` with a null or "yes" in gymfg/success: int(v) traceback."""
    root = copied(tmp_path)
    ones = 1 if value is None else type(value)(1)  # a column of the value's own type
    values = [value if i == 3 else ones for i in range(20)]
    set_column(episodes_table(root), "gymfg/success", values)
    code, out = bc(tmp_path, root, "--select", select)
    assert code == 2
    one_error(capsys, "gymfg/success", "episode 3", "collect recover")
    assert not out.exists()


def test_a_rewritten_episode_index_is_one_error(tmp_path, capsys):
    """#52.11: `--weight grade` with the episode table's episode_index rewritten: KeyError."""
    root = copied(tmp_path)
    set_column(episodes_table(root), "episode_index", [i + 100 for i in range(20)], pa.int64())
    code, out = bc(tmp_path, root, "--weight", "grade")
    assert code == 2
    one_error(capsys, "episode_index", "collect recover")
    assert not out.exists()


def test_shift_auto_without_the_records_is_one_error(tmp_path, capsys):
    """#52.11: `--shift auto` on a `lerobot-edit-dataset delete_episodes` output (LeRobot's
    editing drops the gymfg/* columns): ValueError from a zip."""
    from lerobot.datasets.dataset_tools import delete_episodes
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    edited = tmp_path / "edited"
    delete_episodes(
        LeRobotDataset("gymfg/sample", root=SAMPLE), [0], output_dir=edited, repo_id="gymfg/ed"
    )
    capsys.readouterr()  # LeRobot's progress bars
    code, out = bc(tmp_path, edited, "--shift", "auto")
    assert code == 2
    one_error(capsys, "--shift auto", "collect repair")
    assert not out.exists()


@pytest.mark.parametrize("shift", ["\u00b2", "\u0663", "1e2", "-1"])
def test_a_shift_of_other_digits_is_refused(tmp_path, capsys, shift):
    """#52.11: `--shift ²`: str.isdigit accepts it, int() does not (a traceback)."""
    code, out = bc(tmp_path, SAMPLE, "--shift", shift)
    assert code == 2
    one_error(capsys, "shift=")
    assert not out.exists()


@pytest.mark.slow
def test_a_dataset_merged_with_itself_trains_each_episode_once(tmp_path, caplog):
    """#52.6: LeRobot's merge of a dataset with itself trained on every episode twice with no
    word; now each is trained once and the warning names the repeats."""
    import json

    from lerobot.datasets.dataset_tools import merge_datasets
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    twice = tmp_path / "twice"
    one = LeRobotDataset("gymfg/sample", root=SAMPLE)
    merge_datasets([one, one], output_repo_id="gymfg/twice", output_dir=twice)
    with caplog.at_level(logging.WARNING, logger="gymfg_il.learning.selection"):
        code, out = bc(tmp_path, twice)
    assert code == 0
    assert "holds 20 episode(s) twice" in caplog.text and "20 (= 0)" in caplog.text
    run = json.loads((out / "config.json").read_text())["train"]
    assert run["train_frames"] + run["val_frames"] == 18_000  # the sample's 20 episodes, once


def test_a_flipped_data_page_that_reads_as_numbers_is_refused(tmp_path, capsys):
    """#52.6: a bit flipped inside a data page that still decodes to finite numbers trained
    (exit 0), although `collect recover` finds it by the page's checksum."""
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.collectors.config import CollectConfig

    cfg = CollectConfig(task="altitude", episodes=2, episode_time_s=10, out=tmp_path / "s")
    collect_autopilot(cfg)
    root = tmp_path / "s" / "dataset"
    data = next((root / "data").rglob("*.parquet"))
    raw = data.read_bytes()
    truth = np.array(pq.read_table(data)["action"].to_pylist(), np.float32)
    handle = pq.ParquetFile(data)
    column = handle.metadata.row_group(0).column(handle.schema_arrow.get_field_index("action"))
    start = column.data_page_offset
    for offset in range(start + 64, start + column.total_compressed_size - 64, 97):
        bad = bytearray(raw)
        bad[offset] ^= 0x20
        data.write_bytes(bytes(bad))
        try:  # LeRobot's reader checks no checksum: a flip that still reads as other numbers
            flipped = np.array(pq.read_table(data)["action"].to_pylist(), np.float32)
        except Exception:
            continue
        if np.isfinite(flipped).all() and not np.array_equal(flipped, truth):
            break
    else:
        pytest.fail("no flip in the action pages reads as other finite numbers")
    code, out = bc(tmp_path, root)
    assert code == 2
    one_error(capsys, "action column cannot be read", "collect recover")
    assert not out.exists()


def test_a_session_killed_before_its_dataset_points_to_recover(tmp_path, capsys):
    """#52.12: train bc on a session whose dataset was never written (killed) said "collect
    one" although its logs hold the episodes."""
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.collectors.config import CollectConfig

    cfg = CollectConfig(task="altitude", episodes=1, episode_time_s=4, out=tmp_path / "s")
    collect_autopilot(cfg)
    shutil.rmtree(tmp_path / "s" / "dataset")
    code, out = bc(tmp_path, tmp_path / "s")
    assert code == 2
    one_error(capsys, "collect recover", str(tmp_path / "s"))
    assert not out.exists()
