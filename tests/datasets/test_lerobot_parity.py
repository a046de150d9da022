"""Our column-wise dataset writer against LeRobot's own ``add_frame`` / ``save_episode`` /
``finalize``, on the same two episodes: the metadata, the statistics, the episode table and
the parquet columns must be the same. A LeRobot upgrade that changes its format fails here."""

import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from gymfg_il.datasets import lerobot_api
from gymfg_il.datasets.builder import DatasetBuilder
from gymfg_il.datasets.features import dataset_features
from gymfg_il.errors import ConfigError


def episodes():
    rng = np.random.default_rng(0)
    out = []
    for n in (40, 25):
        out.append(
            {
                "observation.state": rng.normal(size=(n, 3)).astype(np.float32),
                "action": rng.uniform(-1, 1, (n, 4)).astype(np.float32),
                "next.reward": rng.normal(size=n).astype(np.float32),
                "next.done": np.arange(n) == n - 1,
                "intervention": rng.uniform(size=n) < 0.3,
            }
        )
    return out


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    tmp = tmp_path_factory.mktemp("parity")
    features = dataset_features(["alpha", "beta", "gamma"])
    stock = LeRobotDataset.create(
        "gymfg/parity", 10, features, root=tmp / "stock", robot_type="c172p", use_videos=False
    )
    for ep in episodes():
        for i in range(len(ep["action"])):
            stock.add_frame(
                {
                    "observation.state": ep["observation.state"][i],
                    # no name is a catalogue variable: every column is the task's own
                    "observation.environment_state": ep["observation.state"][i],
                    "action": ep["action"][i],
                    "next.reward": ep["next.reward"][i : i + 1],
                    "next.done": ep["next.done"][i : i + 1],
                    "intervention": ep["intervention"][i : i + 1],
                    "task": "hold the altitude",
                }
            )
        stock.save_episode()
    stock.finalize()
    ours = DatasetBuilder(tmp / "ours", "gymfg/parity", 10, features, robot_type="c172p")
    for ep in episodes():
        ours.add_episode(ep, "hold the altitude")
    ours.finalize()
    return tmp / "stock", tmp / "ours"


@pytest.mark.parametrize("name", ["meta/info.json", "meta/stats.json"])
def test_metadata_and_statistics_are_lerobots(both, name):
    stock, ours = both
    assert json.loads((ours / name).read_text()) == json.loads((stock / name).read_text())


@pytest.mark.parametrize(
    "name",
    [
        "meta/episodes/chunk-000/file-000.parquet",
        "data/chunk-000/file-000.parquet",
        "meta/tasks.parquet",
    ],
)
def test_tables_are_lerobots_column_for_column(both, name):
    stock, ours = both
    a, b = pq.read_table(stock / name), pq.read_table(ours / name)
    assert a.schema == b.schema
    for column in a.schema.names:
        assert a.column(column).equals(b.column(column)), column


def test_an_unsupported_lerobot_is_named_with_the_range(monkeypatch):
    import importlib.metadata

    lerobot_api.check_version.cache_clear()
    monkeypatch.setattr(importlib.metadata, "version", lambda name: "0.9.2")
    try:
        with pytest.raises(ConfigError, match=r"LeRobot 0\.9\.2 is installed.*>=0\.6,<0\.7"):
            lerobot_api.check_version()
    finally:
        lerobot_api.check_version.cache_clear()
