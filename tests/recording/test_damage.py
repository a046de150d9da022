"""Damaged files lose only what the damage touches, and say so (red-team findings)."""

import numpy as np
import pytest

from gymfg_il import collect
from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.recording.reader import EmptyLog, LogError, read_log


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("damage")
    cfg = CollectConfig(task="roll", episodes=4, episode_time_s=20, seed=3, out=out)
    result, _ = collect_autopilot(cfg)
    return out, result.log


def test_a_flipped_byte_anywhere_costs_at_most_the_episodes_it_touches(session, tmp_path):
    _, path = session
    data = path.read_bytes()
    original = {e.index: e for e in read_log(path).complete_episodes}
    rng = np.random.default_rng(0)
    offsets = sorted(rng.choice(np.arange(16, len(data) - 16), 60, replace=False))
    kept_some_and_lost_some = 0
    for offset in offsets:
        bad = bytearray(data)
        bad[offset] ^= 0x5A
        broken = tmp_path / "broken.mcap"
        broken.write_bytes(bytes(bad))
        try:
            log = read_log(broken)
        except LogError as err:  # only the session record itself may be beyond repair
            assert "session record is lost" in str(err), (offset, err)
            continue
        kept = {e.index: e for e in log.complete_episodes}
        for k, ep in kept.items():  # what is kept is what was written
            a, b = ep.steps["ego"], original[k].steps["ego"]
            assert np.array_equal(a.state, b.state) and np.array_equal(a.label, b.label)
        lost = set(original) - set(kept)
        if lost:
            assert log.damage, (offset, lost)  # and what was lost is said
            kept_some_and_lost_some += bool(kept)
    assert kept_some_and_lost_some >= 10


def test_recover_and_replay_say_what_was_lost_and_fail(session, tmp_path, capsys):
    _, path = session
    data = bytearray(path.read_bytes())
    chunk = data.find(b"\x06", len(data) // 3)  # inside a chunk in the middle of the file
    data[chunk + 200] ^= 0xFF
    damaged = tmp_path / "damaged"
    (damaged / "logs").mkdir(parents=True)
    (damaged / "logs" / path.name).write_bytes(bytes(data))
    assert collect.main(["recover", str(damaged)]) == 1
    captured = capsys.readouterr()
    assert "damaged logs" in captured.err and "left out" in captured.err
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    kept = LeRobotDataset("x/y", root=damaged / "dataset").num_episodes
    assert 1 <= kept < 4  # the episodes the damage did not touch
    assert collect.main(["replay", str(damaged)]) == 1
    out_err = capsys.readouterr()
    assert "could not read" in out_err.err and "identical" in out_err.out


def test_an_empty_log_is_skipped_not_fatal(session, tmp_path, capsys):
    out = tmp_path / "s"
    (out / "logs").mkdir(parents=True)
    (out / "logs" / "session-killed.mcap").write_bytes(b"")  # killed before its first fsync
    with pytest.raises(EmptyLog):
        read_log(out / "logs" / "session-killed.mcap")
    argv = ["autopilot", "--out", str(out), "--episodes", "1", "--episode-time", "3"]
    assert collect.main([*argv, "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "skipped session-killed.mcap" in text and "1 episodes" in text
    assert collect.main(["recover", str(out)]) == 0


def test_a_dataset_with_a_truncated_data_file_is_rebuilt(session, tmp_path, capsys):
    import shutil

    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    out, path = session
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    data = next((copy / "dataset" / "data").rglob("*.parquet"))
    data.write_bytes(data.read_bytes()[: data.stat().st_size // 2])
    (copy / "dataset.building-123").mkdir()  # left by an interrupted build
    (copy / "dataset.old-456").mkdir()
    assert collect.main(["recover", str(copy)]) == 0
    assert "rebuilt from the logs" in capsys.readouterr().out
    assert LeRobotDataset("x/y", root=copy / "dataset").num_episodes == 4
    assert sorted(p.name for p in copy.iterdir() if "dataset." in p.name)[0].startswith(
        "dataset.broken-"
    )
    assert not list(copy.glob("dataset.building-*")) and not list(copy.glob("dataset.old-*"))
    report = build_from_logs([path], copy / "dataset")
    assert report.added == 0 and report.total_episodes == 4
