"""Camera datasets: frames drawn from the logged states, stored as LeRobot video."""

import os

import numpy as np
import pytest

from gymfg_il.collectors.autopilot import collect_autopilot, record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.datasets.videos import episode_frames
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import read_log
from gymfg_il.viz.camera import Camera

os.environ["HF_HUB_OFFLINE"] = "1"


@pytest.fixture(scope="module")
def camera_dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("images")
    cfg = CollectConfig(
        task="roll", episodes=2, episode_time_s=6, out=out, images=["front", "chase"]
    )
    _, report = collect_autopilot(cfg)
    return out, report


def test_stock_lerobot_decodes_the_frames_the_camera_draws(camera_dataset):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    out, report = camera_dataset
    assert report.added == 2 and report.frames == 120
    ds = LeRobotDataset("gymfg/roll-c172p", root=out / "dataset", video_backend="pyav")
    assert sorted(ds.meta.video_keys) == ["observation.images.chase", "observation.images.front"]
    assert ds.meta.info.features["observation.images.front"]["info"]["video.codec"] == "h264"
    log = read_log(next((out / "logs").glob("*.mcap")))
    drawn = episode_frames(log, log.complete_episodes[1], "ego", Camera(128, 128, "front"))
    for k in (0, 33, 59):  # episode 1 starts at dataset index 60
        item = ds[60 + k]
        image = item["observation.images.front"]
        assert tuple(image.shape) == (3, 128, 128)
        decoded = image.numpy().transpose(1, 2, 0) * 255.0
        # lossless H.264 (crf 0, yuv444p) gives back what was drawn within one level (the
        # colour conversion), and the drawn frame nearest to it is its own
        diffs = [np.abs(decoded - d).mean() for d in drawn]
        assert diffs[k] < 0.6 and np.abs(decoded - drawn[k]).max() <= 1.01
        assert int(np.argmin(diffs)) == k
        assert np.allclose(
            item["observation.state"].numpy(), log.complete_episodes[1].steps["ego"].observation[k]
        )
    stats = ds.meta.stats["observation.images.front"]
    assert np.asarray(stats["mean"]).shape == (3, 1, 1)
    assert 0.2 < float(np.asarray(stats["mean"]).mean()) < 0.9
    card = (out / "dataset" / "README.md").read_text()
    assert "`observation.images.front` (128x128 video)" in card


def test_a_state_only_session_cannot_join_a_camera_dataset(camera_dataset):
    out, _ = camera_dataset
    with pytest.raises(ConfigError, match="camera features"):
        record_autopilot(CollectConfig(task="roll", episodes=1, episode_time_s=2, out=out))


def test_rebuilding_from_the_logs_draws_the_same_videos(camera_dataset, tmp_path):
    out, _ = camera_dataset
    logs = sorted((out / "logs").glob("*.mcap"))
    again = build_from_logs(logs, tmp_path / "again")
    assert again.added == 2
    for view in ("front", "chase"):
        ours = (
            out / "dataset/videos" / f"observation.images.{view}/chunk-000/file-000.mp4"
        ).read_bytes()
        theirs = (
            tmp_path / "again/videos" / f"observation.images.{view}/chunk-000/file-000.mp4"
        ).read_bytes()
        assert ours == theirs


def test_bad_image_settings_are_clear_errors(tmp_path):
    with pytest.raises(ConfigError, match="front, chase"):
        CollectConfig(images=["cockpit"], out=tmp_path)
    with pytest.raises(ConfigError, match="image_size"):
        CollectConfig(images=["front"], image_size=4, out=tmp_path)
    assert CollectConfig(images=["front,chase"], out=tmp_path).images == ["front", "chase"]
