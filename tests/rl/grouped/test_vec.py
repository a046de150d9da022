"""The grouped vector env steps its envs exactly as stable-baselines3's one-process-per-env
vector env does: same seeds, same auto-resets, same infos, bit for bit."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import SubprocVecEnv

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ActionError
from gymfg_il.rl.envs import make_env
from gymfg_il.rl.grouped.vec import GroupedVecEnv, groups_of


def test_groups_split_the_envs_evenly_and_in_order():
    assert groups_of(8, 2) == [range(0, 4), range(4, 8)]
    assert groups_of(5, 2) == [range(0, 3), range(3, 5)]
    assert groups_of(1, 4) == [range(0, 1)]
    assert groups_of(3, 8) == [range(0, 1), range(1, 2), range(2, 3)]


def _run(venv, actions):
    venv.seed(7)
    out = [venv.reset()]
    ends = []
    for a in actions:
        obs, reward, done, infos = venv.step(a)
        out += [obs, reward, done.astype(float)]
        # each env's last reset info (its plan), kept until it resets again
        out.append(np.array([info["target"] for info in venv.reset_infos], dtype=float))
        for i in np.flatnonzero(done):
            ends.append((len(out), i, infos[i]["TimeLimit.truncated"], infos[i]["is_success"]))
            out.append(infos[i]["terminal_observation"])
            episode = dict(infos[i]["episode"])  # stable-baselines3's Monitor, less its clock
            out.append(np.array([episode["r"], episode["l"]]))
    venv.close()
    return out, ends


@pytest.mark.slow
def test_a_grouped_run_repeats_subprocesses_bit_for_bit():
    # 3 s episodes at 10 Hz: the 80 steps cross two auto-resets in every env
    flight = FlightSpec.solo("c172p", "altitude", episode_time_s=3.0)
    # with the success bonus: each end is judged, and its verdict compared too
    fn = partial(make_env, flight.to_dict(), [0.0, 0.0, 0.0, 0.5], [0.3, 0.3, 0.3, 0.3], 0.2)
    rng = np.random.default_rng(0)
    actions = rng.normal(size=(80, 5, 4)).astype(np.float32)
    grouped, grouped_ends = _run(GroupedVecEnv([fn] * 5, 2), actions)
    alone, alone_ends = _run(SubprocVecEnv([fn] * 5), actions)
    assert len(grouped_ends) >= 10 and grouped_ends == alone_ends
    assert all(np.array_equal(a, b) for a, b in zip(grouped, alone, strict=True))
    # and on a machine of one core, where one process steps all five
    one, one_ends = _run(GroupedVecEnv([fn] * 5, 1), actions)
    assert one_ends == alone_ends
    assert all(np.array_equal(a, b) for a, b in zip(one, alone, strict=True))
    # the envs' own seeds: not every env flew the same first episode
    assert not np.array_equal(grouped[0][0], grouped[0][1])


@pytest.mark.slow
def test_attributes_and_methods_reach_the_right_envs():
    flight = FlightSpec.solo("c172p", "altitude", episode_time_s=3.0)
    fn = partial(make_env, flight.to_dict(), [0.0] * 4, [1.0] * 4)
    venv = GroupedVecEnv([fn] * 3, 2)
    try:
        venv.set_attr("tag", "b", indices=[2])
        venv.set_attr("tag", "a", indices=[0, 1])
        assert venv.get_attr("tag") == ["a", "a", "b"]
        assert venv.get_attr("tag", indices=[2, 0]) == ["b", "a"]
        assert venv.get_attr("tag", indices=-1) == ["b"]
        assert venv.env_method("get_wrapper_attr", "tag", indices=1) == ["a"]
        assert venv.env_is_wrapped(Monitor) == [True] * 3
        assert venv.has_attr("tag") and not venv.has_attr("no_such_thing")
        # an env's error comes back as itself, and its process goes on answering
        with pytest.raises(AttributeError, match="no_such_thing"):
            venv.get_attr("no_such_thing", indices=[1])
        venv.reset()
        with pytest.raises(ActionError, match="non-finite"):
            venv.step(np.full((3, 4), np.nan, dtype=np.float32))
        assert venv.get_attr("tag") == ["a", "a", "b"]
    finally:
        venv.close()
    assert not any(p.is_alive() for p in venv.processes)
