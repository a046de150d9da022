import numpy as np
from pettingzoo.test import parallel_api_test

from gymfg_il import Team
from gymfg_il.aircraft import c172p, f15
from gymfg_il.envs import parallel_env
from gymfg_il.tasks import DummyTask, ReachStaticTargetRollTask


def teams():
    red = Team("red", [(f15("red-one"), DummyTask), (f15("red-two"), ReachStaticTargetRollTask)])
    blue = Team("blue", [(c172p("blue-one"), DummyTask)], episode_time_s=30)
    return [red, blue]


def test_parallel_api_test_passes():
    parallel_api_test(parallel_env(teams()), num_cycles=400)


def test_agents_see_their_task_and_the_other_team():
    env = parallel_env(teams())
    obs, _ = env.reset(seed=0)
    assert env.agents == ["red-one", "red-two", "blue-one"]
    assert obs["red-one"]["opponents"].shape == (1, 6)
    assert obs["blue-one"]["opponents"].shape == (2, 6)
    assert obs["red-two"]["observation"].shape == (13,)
    steps = 0
    while env.agents:
        *_, truncs, _ = env.step(dict.fromkeys(env.agents, np.array([0, 0, 0, 0.8])))
        steps += 1
    assert steps == 300 and all(truncs.values())
