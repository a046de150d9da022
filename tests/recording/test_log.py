import numpy as np
import pytest

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.recording.reader import LogError, read_log
from gymfg_il.recording.replay import replay_episode
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.sim.properties import NAMES


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("session")
    cfg = CollectConfig(
        task="heading", dynamic=True, episodes=2, episode_time_s=20, noise=0.05, out=out
    )
    return record_autopilot(cfg)


def test_log_holds_every_step_with_its_session(session):
    log = read_log(session.log)
    assert log.finished and len(log.complete_episodes) == 2
    meta, spec = log.session, log.spec
    assert spec.aircraft == "c172p" and spec.agent_hz == 10 and meta["source"] == "autopilot"
    assert "jsbsim" in meta["versions"] and spec.dynamic is True
    ep = log.complete_episodes[0]
    steps = ep.steps["ego"]
    assert len(steps) == 200 and steps.state.shape == (200, len(NAMES))
    assert ep.start["seed"] == 1000 and ep.end["outcome"] == "time limit"  # collect starts at 1000
    assert steps.observation.shape[1] == len(log.aircraft("ego")["observation_names"])
    # DART noise: every executed control differs from its clean label, the throttle too
    assert all(not np.array_equal(steps.action[:, k], steps.label[:, k]) for k in range(4))


def test_foxglove_location_fix_channel(session):
    from mcap.reader import make_reader

    with open(session.log, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        schemas = {s.name for s in summary.schemas.values()}
        topics = {c.topic for c in summary.channels.values()}
        fix = next(m for _, ch, m in reader.iter_messages(topics=["/gymfg/ego/location"]))
    assert "foxglove.LocationFix" in schemas and "/gymfg/ego/location" in topics
    import json

    msg = json.loads(fix.data)
    assert {"timestamp", "latitude", "longitude", "altitude"} <= set(msg)
    assert msg["altitude"] == pytest.approx(msg["altitude"]) and 500 < msg["altitude"] < 3000


def test_replay_reproduces_states_bit_for_bit(session):
    log = read_log(session.log)
    for ep in log.complete_episodes:
        result = replay_episode(log, ep)
        assert result.identical and result.max_abs_diff == 0.0 and result.steps == 200


def test_replay_notices_a_different_history(session, tmp_path):
    log = read_log(session.log)
    ep = log.complete_episodes[1]
    ep.steps["ego"].action[50, 1] += 0.1  # not what was flown
    result = replay_episode(log, ep)
    assert not result.identical and result.first_mismatch == 50


def test_unfinished_log_keeps_completed_episodes(session, tmp_path):
    data = session.log.read_bytes()
    for cut in (len(data) // 2, len(data) - 50):
        truncated = tmp_path / f"cut{cut}.mcap"
        truncated.write_bytes(data[:cut])
        log = read_log(truncated)
        assert not log.finished
        for ep in log.complete_episodes:
            assert len(ep.steps["ego"]) == 200  # complete ones are whole


def test_writer_never_overwrites_and_reader_rejects_garbage(tmp_path, session):
    with pytest.raises(FileExistsError):
        TrajectoryWriter(session.log, {})
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not an mcap file at all" * 10)
    with pytest.raises(LogError, match="not a readable GymFG trajectory log"):
        read_log(junk)
    with pytest.raises(LogError, match="no trajectory log"):
        read_log(tmp_path / "missing.mcap")


def test_every_chunk_is_message_indexed_as_foxglove_reads_it(session):
    """Foxglove's indexed reader needs each chunk index's message indexes; read every message
    through them (the summary's chunk indexes, then each chunk's message index records)."""
    from mcap.reader import SeekingReader

    path = session.log
    with open(path, "rb") as f:
        reader = SeekingReader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes
        assert all(ci.message_index_offsets for ci in summary.chunk_indexes)
        assert not summary.attachment_indexes
        indexed = sum(summary.statistics.channel_message_counts.values())
        assert indexed == sum(1 for _ in reader.iter_messages())
