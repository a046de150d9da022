import pytest

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs


@pytest.fixture(scope="session")
def tiny_dataset(tmp_path_factory):
    """Six 30-s altitude demonstrations (1,800 frames) with a little DART noise."""
    out = tmp_path_factory.mktemp("tiny")
    cfg = CollectConfig(
        task="altitude", episodes=6, episode_time_s=30, noise=0.02, seed=1000, out=out
    )
    result = record_autopilot(cfg)
    build_from_logs([result.log], out / "dataset")
    return out / "dataset"
