"""Damaged files lose only what the damage touches, and say so (red-team findings)."""

import numpy as np
import pytest

from gymfg_il import collect
from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.recording.reader import EmptyLog, read_log


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
        log = read_log(broken)  # never lost whole: the session record has a copy
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


def _chunks(data):
    """(offset, end) of every chunk record of an intact log."""
    from gymfg_il.recording.mcap_walk import CHUNK, records

    return [(pos, pos + 9 + len(body)) for pos, op, body in records(data, []) if op == CHUNK]


def _episodes_in(data, start, end):
    """The episodes whose step messages the chunk at ``start`` holds (read intact)."""
    from gymfg_il.recording.mcap_walk import chunk_data, records
    from gymfg_il.recording.messages import Sorter

    seen = Sorter()
    for pos, _, body in records(data, []):
        if pos == start:
            # the channel records are in the first chunk: learn them, then sort this one
            seen.chunk(chunk_data(next(b for p, o, b in records(data, []) if o == 0x06)))
            seen.rows.clear()
            seen.chunk(chunk_data(body))
    return {k for k, _ in seen.rows}


@pytest.mark.parametrize("finished", [True, False], ids=["finished", "killed"])
def test_a_bit_in_the_first_chunk_costs_only_the_episodes_it_holds(
    session, tmp_path, capsys, finished
):
    """Red team #32.9: one flipped bit in the first chunk (which holds the channel records)
    lost every episode; now it costs the episodes that chunk holds, and the report names
    them. A killed session's log (no summary) keeps the rest too."""
    _, path = session
    data = path.read_bytes()
    first, end = _chunks(data)[0]
    touched = _episodes_in(data, first, end)
    if not finished:  # as a kill -9 leaves it: no summary, no footer
        data = data[: _chunks(data)[-1][1]]
    bad = bytearray(data)
    bad[(first + end) // 2] ^= 0x10  # inside the compressed records
    folder = tmp_path / "s"
    (folder / "logs").mkdir(parents=True)
    (folder / "logs" / path.name).write_bytes(bytes(bad))
    log = read_log(folder / "logs" / path.name)
    kept = {e.index for e in log.complete_episodes}
    assert touched and kept == {0, 1, 2, 3} - touched
    assert collect.main(["recover", str(folder)]) == 1
    err = capsys.readouterr().err
    assert "fails its CRC check" in err
    for k in sorted(touched):
        assert f"episode {k}" in err
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    assert LeRobotDataset("x/y", root=folder / "dataset").num_episodes == len(kept)


def test_reindex_refuses_a_damaged_log_it_used_to_call_fine(session, tmp_path, capsys):
    """Red team #32.9: `collect reindex` said "already has message indexes" of a log with a
    damaged chunk, and exited 0; a flip outside every chunk is found too (the data CRC)."""
    _, path = session
    data = path.read_bytes()
    chunks = _chunks(data)
    for offset in ((chunks[0][0] + chunks[0][1]) // 2, chunks[0][1] + 12):
        bad = bytearray(data)
        bad[offset] ^= 0x01
        target = tmp_path / f"at-{offset}.mcap"
        target.write_bytes(bytes(bad))
        assert collect.main(["reindex", str(target)]) == 1
        out, err = capsys.readouterr()
        assert "already has message indexes" not in out
        assert f"refused {target}" in err and "damaged" in err
        assert target.read_bytes() == bytes(bad)  # left as it was


@pytest.mark.slow
def test_no_single_flipped_byte_outside_the_chunks_loses_the_whole_log(session, tmp_path):
    """Red team #32.9: the bytes before the first chunk's records (the magic, the header, the
    session record and its copy, the channel table), the first chunk's record header, and the
    summary after the last chunk: a flip in any of them costs at most the first chunk's
    episodes, and is reported."""
    _, path = session
    data = path.read_bytes()
    chunks = _chunks(data)
    first, end = chunks[0]
    spared = {0, 1, 2, 3} - _episodes_in(data, first, end)
    head = range(0, first + 9 + 40, 13)
    tail = range(chunks[-1][1], len(data), 211)
    broken = tmp_path / "broken.mcap"
    for offset in [*head, *tail]:
        bad = bytearray(data)
        bad[offset] ^= 0x04
        broken.write_bytes(bytes(bad))
        log = read_log(broken)  # never "the session record is lost"
        assert {e.index for e in log.complete_episodes} >= spared, offset
        assert log.damage, offset


def _same_episodes(log, original):
    kept = {e.index: e for e in log.complete_episodes}
    assert set(kept) == {e.index for e in original.complete_episodes}
    for ep in original.complete_episodes:
        a, b = kept[ep.index].steps["ego"], ep.steps["ego"]
        assert np.array_equal(a.state, b.state) and np.array_equal(a.label, b.label)


@pytest.mark.parametrize("how", ["duplicated", "swapped"])
def test_chunks_copied_or_moved_with_their_bytes_intact_lose_nothing(session, tmp_path, how):
    """#52.12: a chunk written twice, or two chunks swapped, each with its bytes intact, lost
    that chunk's episode (its steps read twice or out of order); now every episode is read
    as it was written, and the log says what was done to it."""
    _, path = session
    data = path.read_bytes()
    chunks = _chunks(data)
    assert len(chunks) >= 4
    (a, a_end), (b, b_end) = chunks[1], chunks[2]
    if how == "duplicated":
        bad = data[:a_end] + data[a:a_end] + data[a_end:]
    else:
        bad = data[:a] + data[b:b_end] + data[a:a_end] + data[b_end:]
    broken = tmp_path / "broken.mcap"
    broken.write_bytes(bad)
    log = read_log(broken)
    _same_episodes(log, read_log(path))
    said = "a copy of an earlier chunk" if how == "duplicated" else "out of the order"
    assert any(said in note for note in log.damage), log.damage


def test_replay_says_when_there_is_nothing_to_replay_or_the_file_is_cut(session, tmp_path, capsys):
    """#52.6: `replay` of a folder whose only log is empty exited 0, and a log cut in half
    replayed with no word that it was."""
    empty = tmp_path / "empty"
    (empty / "logs").mkdir(parents=True)
    (empty / "logs" / "a.mcap").write_bytes(b"")
    assert collect.main(["replay", str(empty)]) == 2
    assert "nothing to replay" in capsys.readouterr().err
    _, path = session
    data = path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    assert collect.main(["replay", str(cut)]) == 0  # what it holds replays identically
    said = capsys.readouterr()
    assert "identical" in said.out and "DIFFERS" not in said.out
    assert "cut.mcap: the file ends before its footer" in said.err
    assert "2 completed episode(s) in it" in said.err  # of 4: the rest is cut off
