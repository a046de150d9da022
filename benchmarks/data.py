"""The data path: building a LeRobot dataset from MCAP logs against LeRobot's own per-frame
writer, and the training pipeline against ``LeRobotDataset`` + ``DataLoader``."""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.common import Row

SAMPLE = Path(__file__).resolve().parents[1] / "datasets/sample-altitude-c172p/dataset"


def dataset_build(episodes: int) -> Row:
    """frames/s of ``build_from_logs`` (reading the MCAP logs included) beside LeRobot's
    per-frame path (``add_frame`` + ``save_episode`` from frames already in memory)."""
    os.environ["HF_HUB_OFFLINE"] = "1"
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from gymfg_il.collectors.autopilot import record_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets.episode_record import episode_columns
    from gymfg_il.datasets.features import dataset_features
    from gymfg_il.datasets.from_logs import build_from_logs
    from gymfg_il.recording.reader import read_log
    from gymfg_il.sim.properties import task_columns

    tmp = Path(tempfile.mkdtemp(prefix="gymfg-bench-"))
    try:
        result = record_autopilot(CollectConfig(episodes=episodes, out=tmp / "session"))
        t0 = time.perf_counter()
        report = build_from_logs([result.log], tmp / "ours")
        ours = report.frames / (time.perf_counter() - t0)

        log = read_log(result.log)
        ego = log.aircraft("ego")
        t0 = time.perf_counter()
        ds = LeRobotDataset.create(
            "gymfg/bench",
            10,
            dataset_features(ego["observation_names"]),
            root=tmp / "stock",
            use_videos=False,
        )
        env_cols = task_columns(ego["observation_names"])  # the task's own columns
        frames = 0
        for ep in log.complete_episodes:
            cols = episode_columns(ep, "ego")
            for i in range(len(cols["action"])):
                state = cols["observation.state"][i].astype(np.float32)
                ds.add_frame(
                    {
                        "observation.state": state,
                        "observation.environment_state": np.ascontiguousarray(state[env_cols]),
                        "action": cols["action"][i].astype(np.float32),
                        "next.reward": np.array([cols["next.reward"][i]], np.float32),
                        "next.done": np.array([cols["next.done"][i]]),
                        "intervention": np.array([cols["intervention"][i]]),
                        "task": ego["task_description"],
                    }
                )
                frames += 1
            ds.save_episode()
        ds.finalize()
        stock = frames / (time.perf_counter() - t0)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return Row(
        "dataset_build_frames_per_s",
        ours,
        "frames/s",
        20000,
        detail=[
            f"LeRobot add_frame+save_episode {stock:9,.0f} frames/s (from memory)",
            f"ours, from MCAP logs           {ours:9,.0f} frames/s ({ours / stock:.1f}x)",
        ],
    )


def dataset_build_with_images(episodes: int) -> Row:
    """frames/s of ``build_from_logs`` with the front camera: every frame drawn from the
    logged state and encoded to LeRobot video (H.264), beside the same build without it."""
    os.environ["HF_HUB_OFFLINE"] = "1"
    from gymfg_il.collectors.autopilot import record_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets import lerobot_api as lr
    from gymfg_il.datasets.from_logs import build_from_logs

    lr.load()
    tmp = Path(tempfile.mkdtemp(prefix="gymfg-bench-"))
    try:
        cfg = CollectConfig(episodes=episodes, out=tmp / "session", images=["front"])
        result = record_autopilot(cfg)
        plain = build_from_logs([result.log], tmp / "plain", images=[])
        with_images = build_from_logs([result.log], tmp / "images")
        size = sum(f.stat().st_size for f in (tmp / "images/videos").rglob("*.mp4"))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    rate = with_images.frames / with_images.seconds
    return Row(
        "dataset_build_with_images_frames_per_s",
        rate,
        "frames/s",
        1000,
        detail=[
            f"state only (same logs)         {plain.frames / plain.seconds:9,.0f} frames/s",
            f"with the front camera, 128x128 {rate:9,.0f} frames/s "
            f"(video {size / with_images.frames / 1024:.1f} KiB/frame)",
        ],
    )


def train_pipeline(dataset: Path, stock_items: int) -> Row:
    """frames/s delivered to the model: our in-memory tensor batches beside stock
    ``LeRobotDataset`` + ``torch.utils.data.DataLoader`` (per-item ``__getitem__``)."""
    os.environ["HF_HUB_OFFLINE"] = "1"
    import torch
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from gymfg_il.learning.batches import TensorBatches
    from gymfg_il.learning.data import load_frames

    frames = load_frames(dataset)
    batches = TensorBatches(frames, 256, seed=0)
    t0 = time.perf_counter()
    delivered = 0
    for _ in range(20):
        for obs, _act in batches:
            delivered += len(obs)
    ours = delivered / (time.perf_counter() - t0)

    ds = LeRobotDataset("gymfg/bench", root=dataset, video_backend="pyav")
    subset = torch.utils.data.Subset(ds, range(stock_items))
    loader = torch.utils.data.DataLoader(subset, batch_size=256, shuffle=True, num_workers=0)
    t0 = time.perf_counter()
    delivered = 0
    for batch in loader:
        delivered += len(batch["action"])
    stock = delivered / (time.perf_counter() - t0)
    return Row(
        "train_pipeline_frames_per_s",
        ours,
        "frames/s",
        500000,
        detail=[
            f"LeRobotDataset + DataLoader    {stock:11,.0f} frames/s",
            f"ours, in-memory batches        {ours:11,.0f} frames/s ({ours / stock:,.0f}x)",
        ],
    )


def rows(quick: bool) -> list[Row]:
    return [
        dataset_build(5 if quick else 20),
        dataset_build_with_images(3 if quick else 10),
        train_pipeline(SAMPLE, 1000 if quick else 4000),
    ]
