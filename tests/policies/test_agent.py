"""A trained policy as an Agent (``policies.agent``): a recurrent one carries its state from
step to step, the same state at every step (O(1) work), and starts every episode afresh."""

from pathlib import Path

import numpy as np
import pytest
import torch

from gymfg_il.envs.actions import clip
from gymfg_il.learning.data import load_frames
from gymfg_il.learning.memory import remembered
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration import DatasetInfo
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.factory import make_policy
from gymfg_il.policies.normalize import NormalizedPolicy

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"


def sample_episodes(n):
    """The observations of the bundled sample's first ``n`` episodes (900 steps each)."""
    frames = load_frames(SAMPLE)
    return [frames.obs[frames.episode == e] for e in np.unique(frames.episode)[:n]]


def fly(agent, observations):
    return np.array([clip(agent.act(o)) for o in observations])


def test_a_recurrent_agent_steps_as_its_gru_runs_over_the_whole_episode(tiny_gru, carried_state):
    (episode,) = sample_episodes(1)
    agent = PolicyAgent.load(tiny_gru)
    assert agent.stateful
    actions = [clip(agent.act(episode[0]))]
    size = agent._state.shape  # the GRU's hidden state, one per layer
    actions += [clip(agent.act(o)) for o in episode[1:]]
    assert agent._state.shape == size == (1, 1, 16)  # as large at the end: O(1) per step
    carried_state(agent.policy, episode, np.array(actions))


def test_reset_starts_the_next_episode_as_a_fresh_agent_would(tiny_gru):
    first, second = sample_episodes(2)
    agent = PolicyAgent.load(tiny_gru)
    fly(agent, first)
    unreset = fly(agent, second[:1])
    agent.reset()
    again = fly(agent, second)
    fresh = fly(PolicyAgent.load(tiny_gru), second)
    assert np.array_equal(again, fresh)  # bit for bit: the same computation
    assert np.abs(unreset[0] - fresh[0]).max() > 1e-3  # the memory of the first episode


@pytest.mark.parametrize("memory", ["none", "vertical"])
def test_an_mlps_step_in_numpy_is_torchs_act_bit_for_bit(memory):
    frames = load_frames(SAMPLE)
    config = MLPConfig(memory=memory)
    extended = remembered(frames, config)
    info = DatasetInfo(extended.observation_names, frames.fps, frames.flight()[0])
    torch.manual_seed(0)
    module = make_policy(config.for_data(info), extended.obs_stats, frames.action_stats).eval()
    (episode,) = sample_episodes(1)
    fast = generic = None
    for obs in episode[:300]:
        a, fast = module.step(obs, fast)  # the elementwise arithmetic in numpy
        b, generic = NormalizedPolicy.step(module, obs, generic)  # act on a batch of one
        assert a.dtype == b.dtype == np.float64 and a.tobytes() == b.tobytes()
    if memory != "none":  # the memory carried alike: one LoopMemory, the same integrals
        assert fast[0].pids[0].integral == generic[0].pids[0].integral != 0.0
    module.train()  # training (observation noise): torch's own path, the noise drawn there
    module.obs_noise = 1.0
    torch.manual_seed(1)
    noisy, _ = module.step(episode[0])
    assert np.abs(noisy - module.step(episode[0])[0]).max() > 0


def test_a_step_runs_its_layers_on_one_torch_thread_and_leaves_the_setting(monkeypatch):
    frames = load_frames(SAMPLE)
    config = MLPConfig(memory="none")
    info = DatasetInfo(frames.observation_names, frames.fps, frames.flight()[0])
    module = make_policy(config.for_data(info), frames.obs_stats, frames.action_stats).eval()
    seen = []
    module.net.register_forward_hook(lambda *_: seen.append(torch.get_num_threads()))
    (episode,) = sample_episodes(1)
    threads = torch.get_num_threads()
    torch.set_num_threads(2)  # as a user's process may have it
    try:
        module.step(episode[0])  # the MLP's own step
        NormalizedPolicy.step(module, episode[0])  # every other policy's
        assert seen == [1, 1] and torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(threads)
