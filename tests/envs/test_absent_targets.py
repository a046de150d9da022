"""A reward target that is not there (crashed, not joined, left) is visibly absent, offline
and online alike: not in ``ctx.targets``, not in the opponent rows."""

import numpy as np
import pytest

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.envs import OfflineEnv
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks import DummyTask


def watcher(seen):
    """A reward that notes whether blue-1 was there to be seen."""
    return lambda ctx: seen.append("blue-1" in ctx.targets) or 0.0


def test_a_crashed_opponent_leaves_the_rows_and_the_reward_targets_offline():
    seen = []
    red = Team(
        "red",
        [(c172p("red-1"), DummyTask(reward=watcher(seen)))],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=30,
    )
    blue = Team("blue", [(f15("blue-1"), DummyTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent((0.0, 1.0, 0.0, 0.5))])])  # dives
    low = {"blue-1": InitialConditions(altitude_ft=350, airspeed_kts=300)}
    _, rows = env.reset(red, seed=1, options={"initial_conditions": low})
    assert rows.shape == (1, 6)
    crashed_at = None
    for step in range(1, 100):
        _, rows, rewards, *_, info = env.step(np.array([0.0, 0.0, 0.0, 0.7]))
        if crashed_at is None and "blue-1" in info["reasons"]:
            crashed_at = step
            assert rows.shape == (1, 6) and seen[-1]  # seen as it crashed
        elif crashed_at is not None:
            assert rows.shape == (0, 6) and info["opponent_callsigns"] == []
            assert not seen[-1] and np.isfinite(rewards).all()
            break
    assert crashed_at is not None and seen[: crashed_at - 1] == [True] * (crashed_at - 1)
    env.close()


@pytest.mark.network
def test_an_opponent_that_has_not_joined_is_absent_online(tmp_path):
    import subprocess
    import sys

    from gymfg_il.online.client import OnlineEnv

    server = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.serve", "--mode", "open", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    try:
        address = server.stdout.readline().decode().split()[-1]
        seen = []
        red = Team(
            "red",
            [(c172p("red-1"), DummyTask(reward=watcher(seen)))],
            reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        )
        env = OnlineEnv(address, timeout_s=10)
        env.reset(red, seed=0)
        for _ in range(5):
            _, rows, rewards, *_ = env.step(np.array([0.0, 0.0, 0.0, 0.7]))
        assert seen == [False] * 5 and rows.shape == (0, 6) and np.isfinite(rewards).all()
        env.close()
    finally:
        server.terminate()
        server.wait(5)
