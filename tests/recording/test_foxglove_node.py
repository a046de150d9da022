"""Our logs read by Foxglove's own TypeScript reader (``McapIndexedReader`` of ``@mcap/core``)
under Node, and our Foxglove messages checked against ``@foxglove/schemas`` as published.

Needs node and ``tests/node/node_modules`` (``npm ci --prefix tests/node``; ``.ci/run`` does it).
"""

import json
import shutil
import subprocess
from collections import Counter
from pathlib import Path

import jsonschema
import pytest
from mcap.reader import NonSeekingReader
from mcap.writer import IndexType, Writer

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.recording import foxglove, writer
from gymfg_il.recording.indexes import indexed_messages, reindex
from gymfg_il.recording.reader import read_log

NODE_DIR = Path(__file__).resolve().parents[1] / "node"
SCRIPT = NODE_DIR / "foxglove.mjs"
FOXGLOVE = ("foxglove.LocationFix", "foxglove.FrameTransform", "foxglove.SceneUpdate")

pytestmark = [
    pytest.mark.node,
    pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed"),
    pytest.mark.skipif(
        not (NODE_DIR / "node_modules" / "@mcap" / "core").is_dir(),
        reason="tests/node/node_modules is missing: run npm ci --prefix tests/node",
    ),
]


def node(*args):
    return subprocess.run(
        ["node", str(SCRIPT), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=NODE_DIR,
    )


def foxglove_counts(path):
    done = node("counts", path)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def python_counts(path):
    """Messages per topic, streamed by mcap's Python reader without any index."""
    with open(path, "rb") as f:
        counts = Counter(ch.topic for _, ch, _ in NonSeekingReader(f).iter_messages())
    return dict(counts)


@pytest.fixture(scope="module")
def ten_episodes(tmp_path_factory):
    out = tmp_path_factory.mktemp("ten")
    return record_autopilot(CollectConfig(task="altitude", episodes=10, episode_time_s=6, out=out))


def test_foxglove_reads_a_ten_episode_log_completely(ten_episodes):
    path = ten_episodes.log
    got = foxglove_counts(path)
    expected = python_counts(path)
    assert got["topics"] == expected and got["messages"] == sum(expected.values())
    assert Counter(m.topic for m in indexed_messages(path)) == expected
    log = read_log(path)
    steps = sum(len(e.steps["ego"]) for e in log.complete_episodes)
    assert len(log.complete_episodes) == 10 and steps == ten_episodes.steps == 600
    assert got["topics"]["/gymfg/ego/location"] == got["topics"]["/gymfg/ego/step"] == steps
    assert got["topics"]["/gymfg/ego/tf"] == steps + 10  # and one at every reset
    assert {got["schemas"][f"/gymfg/ego/{t}"] for t in ("location", "tf", "scene")} == set(FOXGLOVE)


def test_foxglove_reads_an_old_log_once_reindexed(tmp_path, monkeypatch):
    def old_writer(*args, **kwargs):
        kwargs["index_types"] = IndexType.CHUNK | IndexType.ATTACHMENT | IndexType.METADATA
        return Writer(*args, **kwargs)

    monkeypatch.setattr(writer, "Writer", old_writer)
    path = record_autopilot(CollectConfig(episodes=3, episode_time_s=6, out=tmp_path)).log
    monkeypatch.undo()
    before = node("counts", path)
    assert before.returncode == 1
    assert "chunk index without message indexes" in before.stderr
    expected = python_counts(path)
    assert reindex(path).changed
    got = foxglove_counts(path)
    assert got["topics"] == expected and got["messages"] == sum(expected.values())


@pytest.fixture(scope="module")
def published():
    done = node("schemas", *FOXGLOVE)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_shipped_schemas_are_foxglove_published_ones(published):
    for name in FOXGLOVE:
        assert foxglove.schema(name) == published[name], name


def test_logged_messages_validate_against_published_schemas(ten_episodes, published):
    validators = {n: jsonschema.Draft7Validator(s) for n, s in published.items()}
    checked = Counter()
    with open(ten_episodes.log, "rb") as f:
        for schema, _, message in NonSeekingReader(f).iter_messages():
            if schema is not None and schema.name in validators:
                validators[schema.name].validate(json.loads(message.data))
                checked[schema.name] += 1
    assert set(checked) == set(FOXGLOVE) and checked["foxglove.FrameTransform"] == 610
