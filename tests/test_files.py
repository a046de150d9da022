"""Files that are not files (red team, issue 52): a FIFO in the place of a policy's or a
dataset's file hung eval and train bc (its open waits for a writer), and a link to
/dev/zero or /dev/urandom read until memory ran out. GymFG reads regular files only, up to a
size (``gymfg_il.files``): anything else is one line naming the file, exit status 2, at once.
The same cases for LeRobot checkpoints are in tests/learning/test_hostile_inputs.py, and for
``collect recover`` in tests/datasets/test_recover.py."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from gymfg_il import eval as evaluate
from gymfg_il import train

SAMPLE = Path(__file__).resolve().parents[1] / "datasets/sample-altitude-c172p/dataset"

# what stands in the file's place: a FIFO (open blocks), a device that never ends
SPECIAL = [
    pytest.param(os.mkfifo, id="fifo"),
    pytest.param(lambda path: path.symlink_to("/dev/zero"), id="dev-zero"),
]


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    for needle in needles:
        assert needle in err, err


def replace(path: Path, make) -> None:
    """``path`` (a file) replaced by what ``make`` makes there."""
    path.unlink()
    make(path)


def test_a_regular_file_and_a_link_to_one_are_read(tmp_path):
    from gymfg_il.files import check_regular, read_regular

    (tmp_path / "a.json").write_bytes(b"{}")
    (tmp_path / "link.json").symlink_to(tmp_path / "a.json")
    assert read_regular(tmp_path / "link.json", 2, "fix") == b"{}"
    assert check_regular(tmp_path / "a.json", 2, "fix") == 2
    with pytest.raises(FileNotFoundError):
        read_regular(tmp_path / "absent.json", 2, "fix")


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "make, kind",
    [
        (os.mkfifo, "a FIFO"),
        (lambda p: p.symlink_to("/dev/zero"), "a device"),
        (lambda p: p.symlink_to("/dev/urandom"), "a device"),
        (lambda p: p.mkdir(), "a folder"),
    ],
)
def test_what_is_not_a_regular_file_is_refused_without_reading_it(tmp_path, make, kind):
    from gymfg_il.files import NotRegularFileError, check_regular, read_regular

    make(tmp_path / "config.json")
    for check in (read_regular, check_regular):
        with pytest.raises(NotRegularFileError) as err:
            check(tmp_path / "config.json", 1 << 20, "train the policy again")
        message = str(err.value)
        assert str(tmp_path / "config.json") in message and kind in message, message
        assert "train the policy again" in message


def test_a_file_over_the_limit_is_refused(tmp_path):
    from gymfg_il.files import NotRegularFileError, read_regular

    (tmp_path / "stats.json").write_bytes(b"x" * 2000)
    with pytest.raises(
        NotRegularFileError, match=r"stats\.json is 2000 bytes, more than the 1000 bytes"
    ):
        read_regular(tmp_path / "stats.json", 1000, "rebuild it")


@pytest.fixture(scope="module")
def policy(tmp_path_factory):
    out = tmp_path_factory.mktemp("policy") / "p"
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", "16", "--out", str(out)]
    assert train.main([*argv, "--no-progress"]) == 0
    return out


@pytest.mark.timeout(60)
@pytest.mark.parametrize("make", SPECIAL)
@pytest.mark.parametrize("name", ["config.json", "model.safetensors"])
def test_eval_refuses_a_policy_file_that_is_not_a_file(policy, tmp_path, capsys, name, make):
    broken = tmp_path / "p"
    shutil.copytree(policy, broken)
    replace(broken / name, make)
    assert evaluate.main(["--policy", str(broken), "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, f"{broken / name} is ")


def dataset_file(root: Path, which: str) -> Path:
    if which in ("data", "meta/episodes"):
        return next((root / which).rglob("*.parquet"))
    return root / which


@pytest.mark.timeout(60)
@pytest.mark.parametrize("make", SPECIAL)
@pytest.mark.parametrize(
    "which", ["data", "meta/episodes", "meta/info.json", "meta/stats.json", "meta/tasks.parquet"]
)
def test_train_refuses_a_dataset_file_that_is_not_a_file(tmp_path, capsys, which, make):
    root = tmp_path / "dataset"
    shutil.copytree(SAMPLE, root)
    path = dataset_file(root, which)
    replace(path, make)
    argv = ["bc", "--dataset", str(root), "--epochs", "1", "--out", str(tmp_path / "p")]
    assert train.main([*argv, "--no-progress"]) == 2
    one_error(capsys, str(path.relative_to(root)), "not a regular file")
    assert not (tmp_path / "p").exists()
