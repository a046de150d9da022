import operator
import os
import threading

import pytest

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError, EnvStateError
from gymfg_il.recording.reader import read_log
from gymfg_il.rollout import AgentSpec, fly_many
from gymfg_il.workers import Workers, map_seeds


def test_two_workers_give_what_one_gives(tmp_path):
    spec = FlightSpec.solo("f15", "roll", dynamic=True, episode_time_s=10)
    one = fly_many(spec, AgentSpec.controller(), [4, 5, 6], workers=1)
    two = fly_many(spec, AgentSpec.controller(), [4, 5, 6], workers=2)
    assert [e.seed for e in two] == [4, 5, 6]
    for a, b in zip(one, two, strict=True):
        assert (a.rewards == b.rewards).all() and (a.actions == b.actions).all()
    logs = []
    for workers in (1, 2):
        cfg = CollectConfig(
            task="pitch", episodes=3, episode_time_s=5, noise=0.1, out=tmp_path / f"w{workers}"
        )
        logs.append(read_log(record_autopilot(cfg, workers=workers).log))
    for a, b in zip(logs[0].complete_episodes, logs[1].complete_episodes, strict=True):
        sa, sb = a.steps["ego"], b.steps["ego"]
        assert (sa.state == sb.state).all() and (sa.action == sb.action).all()


def test_kept_workers_serve_several_calls_alike_and_refuse_use_after_close(tmp_path):
    spec = FlightSpec.solo("c172p", "roll", episode_time_s=5)
    one = fly_many(spec, AgentSpec.controller(), [1, 2, 3], workers=1)
    # fork while this process runs no other thread (an earlier test's tqdm monitor may)
    expected = "fork" if threading.active_count() == 1 else "forkserver"
    with Workers(2) as workers:
        assert workers._pool._ctx.get_start_method() == expected
        first = fly_many(spec, AgentSpec.controller(), [1, 2, 3], workers=workers)
        other = fly_many(
            FlightSpec.solo(task="pitch", episode_time_s=5), AgentSpec.controller(), [1, 2], workers
        )
        again = fly_many(spec, AgentSpec.controller(), [3, 2, 1], workers=workers)
        pending = map_seeds(operator.add, (10,), [1, 2, 3], workers)
        assert next(pending) == 11
    assert [e.seed for e in other] == [1, 2]
    for a, b, c in zip(one, first, again[::-1], strict=True):
        assert (a.actions == b.actions).all() and (a.actions == c.actions).all()
    with pytest.raises(EnvStateError, match="closed while"):
        next(pending)  # a closed pool's results would never come: an error, not a hang
    with pytest.raises(EnvStateError, match="closed"):
        list(map_seeds(operator.add, (10,), [1], workers))
    for bad in (0, -1, True):
        with pytest.raises(ConfigError, match=f"workers={bad!r}"):
            Workers(bad)
        with pytest.raises(ConfigError, match=f"workers={bad!r}"):
            list(map_seeds(operator.add, (10,), [1], bad))


def test_a_checkpoint_rewritten_in_place_gets_a_new_cache_key(tmp_path):
    ckpt = tmp_path / "policy"
    ckpt.mkdir()
    (ckpt / "model.safetensors").write_bytes(b"v1")
    (ckpt / "config.json").write_text("{}")
    before = AgentSpec.policy(ckpt).key()
    (ckpt / "loss.png").write_bytes(b"unrelated")
    assert AgentSpec.policy(ckpt).key() == before  # other files do not matter
    os.utime(ckpt / "model.safetensors", ns=(1, 1))
    assert AgentSpec.policy(ckpt).key() != before
