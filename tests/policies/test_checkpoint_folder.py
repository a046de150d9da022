"""What a save may replace (``policies.checkpoint_folder.check_out``): a policy's own files
only, checked by kind and content, not by name alone (red team, issue 52). A folder named
``loss.png`` or a ``tensorboard/`` holding a user's notes is the user's, and refused; a
``train ppo --checkpoints`` folder is a policy's, and a later save replaces it."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from gymfg_il import train
from gymfg_il.errors import ConfigError
from gymfg_il.policies.checkpoint_folder import check_out

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"
EVENTS = "events.out.tfevents.1700000000.host.4242.0"  # as torch's SummaryWriter names them


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    assert err.count("\n") == 1, err
    for needle in needles:
        assert needle in err, err


def bc_policy_files(folder: Path) -> None:
    """What ``train bc`` writes (contents do not matter to the check)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("config.json", "model.safetensors", "loss.png", "train_log.json"):
        (folder / name).write_bytes(b"x")


def ppo_policy_files(folder: Path, checkpoints: bool = False) -> None:
    """What ``train ppo`` writes: the policy, its curve, stable-baselines3's TensorBoard log
    (``tensorboard/ppo_1/events...``) and, with --checkpoints, each evaluated actor as a
    policy folder ``checkpoints/step-N`` (and ``checkpoints/average``)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("config.json", "model.safetensors", "curve.json", "curve.png"):
        (folder / name).write_bytes(b"x")
    (folder / "tensorboard" / "ppo_1").mkdir(parents=True)
    (folder / "tensorboard" / "ppo_1" / EVENTS).write_bytes(b"x")
    if checkpoints:
        for step in ("step-0", "step-1024", "average"):
            (folder / "checkpoints" / step).mkdir(parents=True)
            for name in ("config.json", "model.safetensors"):
                (folder / "checkpoints" / step / name).write_bytes(b"x")


def test_a_policys_own_folders_may_be_replaced(tmp_path):
    bc_policy_files(tmp_path / "bc")
    ppo_policy_files(tmp_path / "ppo")
    for out in (tmp_path / "bc", tmp_path / "ppo", tmp_path / "new", tmp_path / "empty"):
        (tmp_path / "empty").mkdir(exist_ok=True)
        check_out(out)  # no error


def _user_file(folder: Path, name: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text("the user's")
    return folder / name


@pytest.mark.parametrize(
    "damage, named",
    [
        (lambda p: _user_file(p / "loss.png", "photo.jpg"), "loss.png"),
        (lambda p: _user_file(p / "config.json", "notes.txt"), "config.json"),
        (lambda p: _user_file(p / "tensorboard", "notes.txt"), "tensorboard/notes.txt"),
        (lambda p: _user_file(p / "tensorboard" / "ppo_1", "run.csv"), "tensorboard/ppo_1/run.csv"),
        (lambda p: os.mkfifo(p / "model.safetensors"), "model.safetensors"),
        (lambda p: (p / "curve.json").symlink_to(_user_file(p.parent, "mine.json")), "curve.json"),
    ],
)
def test_a_policy_name_holding_a_users_files_is_refused(tmp_path, damage, named):
    out = tmp_path / "p"
    out.mkdir()
    damage(out)
    before = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))
    with pytest.raises(ConfigError) as err:
        check_out(out)
    assert f"({named}: " in str(err.value)
    assert "give a new or empty folder" in str(err.value)
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) == before


def test_train_bc_never_replaces_a_users_tensorboard_folder(tmp_path, capsys):
    out = tmp_path / "p"
    bc_policy_files(out)
    mine = _user_file(out / "tensorboard", "experiment-notes.md")
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--out", str(out), "--no-progress"]
    assert train.main(argv) == 2
    one_error(capsys, "tensorboard/experiment-notes.md", "give a new or empty folder")
    assert mine.read_text() == "the user's"


def test_a_ppo_checkpoints_folder_is_replaced_by_a_later_save(tmp_path, capsys):
    """A ``train ppo --checkpoints`` folder takes a later ``train bc`` (or ``train ppo``):
    the save replaces it whole, checkpoints and all."""
    out = tmp_path / "p"
    ppo_policy_files(out, checkpoints=True)
    check_out(out)  # no error
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--out", str(out), "--no-progress"]
    assert train.main(argv) == 0, capsys.readouterr().err
    held = sorted(p.name for p in out.iterdir())
    assert held == ["config.json", "loss.png", "model.safetensors", "train_log.json"]


@pytest.mark.parametrize(
    "damage, named",
    [
        (lambda p: _user_file(p / "checkpoints", "notes.txt"), "checkpoints/notes.txt"),
        (lambda p: _user_file(p / "checkpoints" / "step-0", "notes.txt"),
         "checkpoints/step-0/notes.txt"),
        (lambda p: _user_file(p / "checkpoints" / "mine", "config.json"), "checkpoints/mine"),
        (lambda p: _user_file(p / "checkpoints" / "step-0" / "config.json", "x"),
         "checkpoints/step-0/config.json"),
        (lambda p: shutil.rmtree(p / "checkpoints") or _user_file(p, "checkpoints"),
         "checkpoints"),
    ],
)  # fmt: skip
def test_a_checkpoints_folder_holding_a_users_files_is_refused(tmp_path, damage, named):
    out = tmp_path / "p"
    ppo_policy_files(out, checkpoints=True)
    if (out / "checkpoints" / "step-0" / "config.json").exists():
        (out / "checkpoints" / "step-0" / "config.json").unlink()
    damage(out)
    with pytest.raises(ConfigError) as err:
        check_out(out)
    assert f"({named}: " in str(err.value)


def test_an_out_that_is_a_link_is_refused_before_training(tmp_path, capsys):
    """#52.12: `train bc --out LINK` trained, then failed to save with "free some space"."""
    from gymfg_il import train

    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "link").symlink_to(real)
    sample = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"
    argv = ["bc", "--dataset", str(sample), "--epochs", "1", "--no-progress"]
    assert train.main([*argv, "--out", str(tmp_path / "link")]) == 2
    err = capsys.readouterr().err
    assert "is a link" in err and f"--out {real}" in err and "training" not in err
    assert (tmp_path / "link").is_symlink() and list(real.iterdir()) == []
