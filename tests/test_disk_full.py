"""A full disk is one line "error: the disk is full ..." with exit status 2, and loses
nothing saved before (red team, issue 52.9: `train bc`, `train ppo`, `collect autopilot` and
`collect recover` ended in tracebacks: SafetensorError, errno 28). The disk is a real one: a
small tmpfs mounted for the test (as root, which CI is; skipped elsewhere)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from gymfg_il import collect, train

SAMPLE = Path(__file__).resolve().parent.parent / "datasets/sample-altitude-c172p/dataset"


@pytest.fixture
def disk(tmp_path):
    """A 4 MiB file system of its own at ``tmp_path/disk``."""
    where = tmp_path / "disk"
    where.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a small tmpfs needs root")
    made = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(where)], capture_output=True
    )
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")
    yield where
    subprocess.run(["umount", "-l", str(where)], check=True)


def fill(where: Path, leave: int) -> None:
    """Take all but ``leave`` bytes of the file system at ``where``."""
    free = shutil.disk_usage(where).free - leave
    with open(where / "filler", "wb") as f:
        os.posix_fallocate(f.fileno(), 0, max(free, 1))


def one_line(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    (line,) = [x for x in err.splitlines() if x.startswith("error: ")]
    assert "the disk is full" in line and "free some space" in line
    return line


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_train_bc_on_a_full_disk_keeps_the_old_policy(disk, tmp_path, capsys):
    out = disk / "policy"
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", "16", "--no-progress"]
    assert train.main([*argv, "--out", str(out)]) == 0
    before = files(out)
    fill(disk, 16 * 1024)
    assert train.main([*argv, "--out", str(out), "--seed", "1"]) == 2
    one_line(capsys)
    assert files(out) == before  # the old policy, whole
    assert sorted(p.name for p in disk.iterdir()) == ["filler", "policy"]  # no staging left


def test_collect_autopilot_on_a_full_disk_is_one_line(disk, capsys):
    fill(disk, 64 * 1024)
    argv = ["autopilot", "--task", "roll", "--episodes", "20", "--episode-time", "20"]
    assert collect.main([*argv, "--out", str(disk / "s"), "--no-progress"]) == 2
    one_line(capsys)


def test_recover_on_a_full_disk_is_one_line_and_loses_no_log(disk, tmp_path, capsys):
    session = tmp_path / "s"
    argv = ["autopilot", "--task", "roll", "--episodes", "4", "--episode-time", "6"]
    assert collect.main([*argv, "--out", str(session), "--no-progress"]) == 0
    shutil.copytree(session / "logs", disk / "s" / "logs")
    logs = files(disk / "s" / "logs")
    fill(disk, 8 * 1024)
    capsys.readouterr()
    assert collect.main(["recover", str(disk / "s")]) == 2
    one_line(capsys)
    assert files(disk / "s" / "logs") == logs
    (disk / "filler").unlink()
    assert collect.main(["recover", str(disk / "s")]) == 0  # with room again, all of it
    assert "4 episodes (+4" in capsys.readouterr().out
