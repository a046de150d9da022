import hashlib
import os

import numpy as np
import pytest

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import read_log
from gymfg_il.tasks.grades import GRADES

os.environ["HF_HUB_OFFLINE"] = "1"


def tree_digest(root):
    h = hashlib.sha256()
    for dirpath, _, files in sorted(os.walk(root)):
        for name in sorted(files):
            path = os.path.join(dirpath, name)
            h.update(path.encode())
            with open(path, "rb") as f:
                h.update(f.read())
    return h.hexdigest()


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("collect")
    cfg = CollectConfig(task="altitude", episodes=3, episode_time_s=15, out=out)
    result = record_autopilot(cfg)
    report = build_from_logs([result.log], out / "dataset")
    return out, result, report


def test_dataset_opens_with_stock_lerobot_and_equals_the_log(built):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    out, result, report = built
    assert report.added == 3 and report.frames == 450
    ds = LeRobotDataset("anything/name", root=out / "dataset")
    assert ds.num_episodes == 3 and len(ds) == 450 and ds.fps == 10
    log = read_log(result.log)
    names = log.aircraft("ego")["observation_names"]
    assert ds.meta.features["observation.state"]["names"] == names
    assert ds.meta.features["action"]["names"] == ["aileron", "elevator", "rudder", "throttle"]
    for k, ep in enumerate(log.complete_episodes):
        steps = ep.steps["ego"]
        start = k * 150
        frames = [ds[start + i] for i in (0, 77, 149)]
        for frame, i in zip(frames, (0, 77, 149), strict=True):
            assert np.array_equal(
                frame["observation.state"].numpy(), steps.observation[i].astype(np.float32)
            )
            assert np.array_equal(frame["action"].numpy(), steps.label[i].astype(np.float32))
            assert frame["next.reward"].item() == pytest.approx(steps.reward[i], rel=1e-6)
            assert bool(frame["next.done"]) == (i == 149)
            assert frame["task"].startswith("Climb or descend")
        meta = ds.meta.episodes[k]
        assert meta["gymfg/seed"] == 1000 + k and meta["gymfg/source"] == "autopilot"
        assert meta["gymfg/aircraft"] == "c172p" and meta["gymfg/interventions"] == 0
        assert meta["gymfg/target"] == pytest.approx(ep.start_of("ego")["target"])


def test_rebuilding_adds_nothing_twice_and_keeps_data(built):
    out, result, _ = built
    before = tree_digest(out / "dataset")
    again = build_from_logs([result.log], out / "dataset")
    assert again.added == 0 and again.total_episodes == 3
    assert tree_digest(out / "dataset") != "" and before  # still readable below
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    assert LeRobotDataset("x/y", root=out / "dataset").num_episodes == 3


def test_appending_mismatched_features_is_refused_and_touches_nothing(built, tmp_path):
    out, _, _ = built
    before = tree_digest(out / "dataset")
    other = CollectConfig(task="roll", episodes=1, episode_time_s=5, out=tmp_path / "roll")
    roll_log = record_autopilot(other).log
    with pytest.raises(ConfigError, match="observation"):
        build_from_logs([roll_log], out / "dataset")
    with pytest.raises(ConfigError, match="features differ"):
        record_autopilot(CollectConfig(task="roll", episodes=1, episode_time_s=5, out=out))
    assert tree_digest(out / "dataset") == before
    assert len(list((out / "logs").glob("*.mcap"))) == 1  # nothing was flown or logged


def test_a_broken_dataset_is_set_aside_and_rebuilt(built, tmp_path):
    out, result, _ = built
    import shutil

    root = tmp_path / "dataset"
    shutil.copytree(out / "dataset", root)
    (root / "meta" / "info.json").write_text("{ broken")
    report = build_from_logs([result.log], root)
    assert report.rebuilt and report.total_episodes == 3
    assert list(tmp_path.glob("dataset.broken-*"))


def test_verdict_pilot_and_mark_columns_take_only_what_they_hold(built):
    import dataclasses

    from gymfg_il.datasets.episode_record import episode_metadata

    _, result, _ = built
    log = read_log(result.log)
    episode = log.episodes[0]
    callsign = next(iter(episode.steps))
    plain = episode_metadata(log, episode, callsign)
    # the autopilot's collector judges and grades its episodes as the manual window does
    assert plain["success"] in (0, 1) and plain["verdict"].startswith("over the last 10 s")
    assert plain["grade"] in GRADES and (plain["success"] == 1) == (plain["grade"] != GRADES[3])
    assert (plain["pilot"], plain["mark"], plain["late_frames"], plain["rate_hz"]) == (
        "",
        "",
        -1,
        -1,
    )
    hostile = dataclasses.replace(
        episode,
        start={**episode.start, "pilot": ["not", "a", "name"]},
        end={
            **(episode.end or {}),
            "success": [1],
            "verdict": {"x": 1},
            "grade": "superb",
            "late_frames": True,
            "rate_hz": float("inf"),
            "jitter_ms": "2",
        },
    )
    columns = episode_metadata(log, hostile, callsign)
    assert (columns["success"], columns["verdict"], columns["pilot"]) == (-1, "", "")
    assert (columns["grade"], columns["late_frames"], columns["rate_hz"]) == ("", -1, -1.0)
    assert columns["jitter_ms"] == -1.0
    long = dataclasses.replace(episode, start={**episode.start, "pilot": "x" * 5000})
    assert len(episode_metadata(log, long, callsign)["pilot"]) == 200


def test_a_wall_clock_column_where_frames_were_flown_in_real_time(built, tmp_path):
    """A frame flown in real time keeps the wall clock its input was read at (seconds from
    the episode's first frame; the first frame's Unix time per episode); a dataset with the
    column reads -1 for frames flown faster; one without it takes real-time frames without
    their clock; the log's clock is hostile until checked."""
    import dataclasses

    import pyarrow.parquet as pq

    from gymfg_il.datasets.builder import DatasetBuilder
    from gymfg_il.datasets.episode_record import episode_columns, episode_metadata
    from gymfg_il.datasets.features import dataset_features
    from gymfg_il.recording.reader import _clock

    out, result, _ = built
    assert "wall_time" not in pq.read_schema(next((out / "dataset/data").rglob("*.parquet")))
    log = read_log(result.log)
    fast = log.complete_episodes[0]
    steps = fast.steps["ego"]
    assert (steps.wall_time == -1).all()
    assert episode_metadata(log, fast, "ego")["wall_start"] == -1
    clock = 1.8e9 + 0.04 * np.arange(len(steps))
    timed = dataclasses.replace(fast, steps={"ego": dataclasses.replace(steps, wall_time=clock)})
    columns = episode_columns(timed, "ego")
    np.testing.assert_allclose(columns["wall_time"], 0.04 * np.arange(len(steps)), atol=1e-6)
    assert episode_metadata(log, timed, "ego")["wall_start"] == 1.8e9
    names = log.aircraft("ego")["observation_names"]
    read = {}
    for name, clocked in (("clocked", True), ("plain", False)):
        features = dataset_features(names, (), 128, clocked)
        builder = DatasetBuilder(tmp_path / name, "gymfg/t", 10, features)
        builder.add_episode(columns, "hold")
        builder.add_episode(episode_columns(fast, "ego"), "hold")
        with pytest.raises(ConfigError, match=r"no features \['bogus'\]"):
            builder.add_episode({**columns, "bogus": columns["action"]}, "hold")
        builder.finalize()
        read[name] = pq.read_table(next((tmp_path / name / "data").rglob("*.parquet")))
    wall = read["clocked"]["wall_time"].to_numpy()
    np.testing.assert_allclose(wall[:150], 0.04 * np.arange(150), atol=1e-5)
    assert (wall[150:] == -1).all() and "wall_time" not in read["plain"].column_names
    assert [_clock(v) for v in (1.5, 3, "2", True, float("nan"), -4.0, None)] == [
        1.5, 3.0, -1, -1, -1, -1, -1,
    ]  # fmt: skip
