import pytest


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
