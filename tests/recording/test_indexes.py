"""Re-indexing logs written before message indexes, as Foxglove's indexed reader needs them."""

import os

import numpy as np
import pytest
from mcap.reader import NonSeekingReader
from mcap.writer import IndexType, Writer

from gymfg_il import collect
from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.recording import indexes, writer
from gymfg_il.recording.indexes import index_problems, indexed_messages, reindex
from gymfg_il.recording.reader import LogError, read_log

OLD_INDEXES = IndexType.CHUNK | IndexType.ATTACHMENT | IndexType.METADATA


def old_writer(*args, **kwargs):
    """mcap's Writer as the log writer used it before message indexes."""
    kwargs["index_types"] = OLD_INDEXES
    return Writer(*args, **kwargs)


@pytest.fixture(scope="module")
def old_log(tmp_path_factory):
    """A log written with the old index settings: chunk, attachment and metadata indexes, no
    message indexes."""
    out = tmp_path_factory.mktemp("old")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(writer, "Writer", old_writer)
        result = record_autopilot(
            CollectConfig(task="altitude", episodes=3, episode_time_s=8, out=out)
        )
    return result.log


def streamed(path):
    """Every message in file order, read without any index."""
    with open(path, "rb") as f:
        return [
            (ch.topic, m.sequence, m.log_time, m.publish_time, m.data)
            for _, ch, m in NonSeekingReader(f).iter_messages(log_time_order=False)
        ]


def test_old_log_is_what_foxglove_cannot_read(old_log):
    problems = index_problems(old_log)
    assert any("no message index" in p for p in problems)
    assert "an empty attachment index group" in problems
    with pytest.raises(LogError, match="no message index"):
        next(indexed_messages(old_log))


def test_reindex_in_place_keeps_every_message_in_order(old_log, tmp_path):
    path = tmp_path / old_log.name
    path.write_bytes(old_log.read_bytes())
    before, log_before = streamed(path), read_log(path)
    r = reindex(path)
    assert r.changed and r.messages == len(before) > 3 * 80 * 3
    assert index_problems(path) == []
    through_indexes = [
        (m.topic, m.sequence, m.log_time, m.publish_time, m.data) for m in indexed_messages(path)
    ]
    assert through_indexes == before
    log_after = read_log(path)
    assert log_after.finished and log_after.session == log_before.session
    assert len(log_after.complete_episodes) == 3
    for a, b in zip(log_before.complete_episodes, log_after.complete_episodes, strict=True):
        assert np.array_equal(a.steps["ego"].observation, b.steps["ego"].observation)
        assert np.array_equal(a.steps["ego"].state, b.steps["ego"].state)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


def test_an_indexed_log_is_left_untouched(old_log, tmp_path):
    path = tmp_path / old_log.name
    path.write_bytes(old_log.read_bytes())
    reindex(path)
    data, stat = path.read_bytes(), path.stat()
    again = reindex(path)
    assert not again.changed and again.problems == ()
    assert path.read_bytes() == data and path.stat().st_mtime_ns == stat.st_mtime_ns


def test_a_log_without_messages_is_left_untouched(tmp_path):
    path = tmp_path / "quit-before-flying.mcap"  # a session quit before its first episode
    session = {"callsigns": ["ego"], "aircraft": {"ego": {"team": "ego"}}, "dt": 0.1}
    writer.TrajectoryWriter(path, session).close()
    data = path.read_bytes()
    assert index_problems(path) == []
    assert not reindex(path).changed and path.read_bytes() == data


def test_damaged_and_cut_logs_are_refused_and_left_as_they_were(old_log, tmp_path):
    data = old_log.read_bytes()
    with open(old_log, "rb") as f:
        from mcap.reader import SeekingReader

        chunk = SeekingReader(f).get_summary().chunk_indexes[1]
    damaged = bytearray(data)
    at = chunk.chunk_start_offset + chunk.chunk_length // 2
    damaged[at : at + 16] = bytes(16)
    cases = {"damaged.mcap": (bytes(damaged), "damaged"), "cut.mcap": (data[:-500], "no footer")}
    for name, (content, why) in cases.items():
        path = tmp_path / name
        path.write_bytes(content)
        with pytest.raises(LogError, match=why):
            reindex(path)
        assert path.read_bytes() == content
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.mcap", "damaged.mcap"]


def test_a_crash_before_the_rename_leaves_the_original(old_log, tmp_path, monkeypatch):
    path = tmp_path / old_log.name
    path.write_bytes(old_log.read_bytes())

    def crash(*args):
        raise KeyboardInterrupt  # e.g. Ctrl-C while the copy is being checked

    monkeypatch.setattr(indexes, "_verify", crash)
    with pytest.raises(KeyboardInterrupt):
        reindex(path)
    assert path.read_bytes() == old_log.read_bytes()
    assert os.listdir(tmp_path) == [path.name]


def test_collect_reindex_verb(old_log, tmp_path, capsys):
    logs = tmp_path / "session" / "logs"
    logs.mkdir(parents=True)
    (logs / "a.mcap").write_bytes(old_log.read_bytes())
    assert collect.main(["reindex", str(tmp_path / "session")]) == 0
    assert "reindexed" in capsys.readouterr().out
    assert collect.main(["reindex", str(logs / "a.mcap")]) == 0
    assert "left untouched" in capsys.readouterr().out
    (logs / "b.mcap").write_bytes(old_log.read_bytes()[:-100])
    assert collect.main(["reindex", str(logs)]) == 1
    assert "refused" in capsys.readouterr().err
