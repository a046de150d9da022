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


def _far_target_seeds(env, count, min_error_ft=150.0):
    """The first held-out seeds (from 0; demonstrations use 1000+) whose altitude target lies
    at least ``min_error_ft`` from the start. Starts are trimmed: hands-off flight holds the
    start altitude, so a target a few feet away is one a zero-action agent already holds, and
    beating it there says nothing about what the policy learned."""
    at = env.observation_names.index("altitude_ft_error")
    seeds = []
    seed = 0
    while len(seeds) < count:
        obs, _ = env.reset(seed=seed)
        if abs(obs[at]) >= min_error_ft:
            seeds.append(seed)
        seed += 1
    return seeds


@pytest.fixture
def far_target_seeds():
    return _far_target_seeds
