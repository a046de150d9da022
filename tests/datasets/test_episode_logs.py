"""Log names read from a dataset or base-episodes.json stay file names inside logs/ (red team
finding #32.2: DAgger wrote a file beside its --out folder)."""

import json
import os

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.episode_logs import (
    BASE_EPISODES,
    EpisodeRef,
    base_refs,
    link_base_logs,
    log_name_problem,
    unrebuildable,
)
from gymfg_il.errors import ConfigError

HOSTILE = ["../../payload.txt", "/etc/passwd", "sub/x.mcap", "..", ".", "", "a\x00b.mcap"]


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """A session whose dataset's episode table names hostile logs (episode 0 and 1)."""
    top = tmp_path_factory.mktemp("base")
    out = top / "deep" / "base"
    collect_autopilot(CollectConfig(task="roll", episodes=3, episode_time_s=2, out=out))
    (table_path,) = (out / "dataset" / "meta" / "episodes").rglob("*.parquet")
    table = pq.read_table(table_path)
    names = table["gymfg/log"].to_pylist()
    names[0], names[1] = "../../payload.txt", "/etc/hostname"
    index = table.schema.get_field_index("gymfg/log")
    table = table.set_column(index, "gymfg/log", pa.array(names))
    pq.write_table(table, table_path)
    (top / "deep" / "payload.txt").write_text("not a log")  # where ../../ reaches from logs/
    return out


def test_dagger_links_no_file_outside_its_logs_folder(base, tmp_path):
    out = tmp_path / "dagger"
    problems = link_base_logs(base / "dataset", out / "logs")
    assert not (tmp_path / "payload.txt").exists()  # was created beside --out
    assert sorted(p.name for p in (out / "logs").iterdir()) == sorted(
        [BASE_EPISODES, next((base / "logs").glob("*.mcap")).name]
    )
    assert len(problems) == 2
    assert "'../../payload.txt' is not a log file name" in problems[0]
    assert "'/etc/hostname' is not a log file name" in problems[1]
    record = json.loads((out / "logs" / BASE_EPISODES).read_text())
    assert [e["log"] for e in record["episodes"]][:2] == [None, None]


@pytest.mark.parametrize("name", HOSTILE)
def test_every_name_that_is_no_plain_file_name_is_refused(name):
    assert log_name_problem(name) is not None
    assert log_name_problem("autopilot-20261126-154648-7468-492813.mcap") is None


def test_a_hostile_base_episodes_file_is_refused_by_name(tmp_path):
    (tmp_path / BASE_EPISODES).write_text(
        json.dumps(
            {"episodes": [{"index": 0, "log": "../x.mcap", "log_episode": 0, "callsign": "ego"}]}
        )
    )
    with pytest.raises(ConfigError, match=r"'\.\./x\.mcap' is not a log file name"):
        base_refs([tmp_path])


def test_unrebuildable_looks_at_no_path_outside_logs(tmp_path):
    (tmp_path / "outside.mcap").write_text("x")
    logs = tmp_path / "logs"
    logs.mkdir()
    lines = unrebuildable([(0, EpisodeRef("../outside.mcap", 0, "ego"))], set(), logs)
    assert len(lines) == 1 and "'../outside.mcap' is not a log file name" in lines[0]
    assert "not a completed episode" not in lines[0]
    assert os.path.exists(tmp_path / "outside.mcap")
