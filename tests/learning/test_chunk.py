"""The chunking policy: its training windows, its temporal ensembling, and that it trains
and flies."""

import numpy as np
import pytest
import torch

from gymfg_il.agent import ConstantAgent
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.learning.batches import TensorBatches, window_indices
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.data import Frames
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration_chunk import ChunkConfig
from gymfg_il.policies.modeling_chunk import ChunkPolicy
from gymfg_il.rollout import Rollout


def frames_of(episodes, frame_numbers):
    n = len(episodes)
    stats = {"mean": np.zeros(2), "std": np.ones(2)}
    return Frames(
        obs=np.arange(n, dtype=np.float32)[:, None].repeat(2, 1),
        action=np.arange(n, dtype=np.float32)[:, None].repeat(4, 1),
        episode=np.array(episodes),
        frame=np.array(frame_numbers),
        observation_names=["a", "b"],
        action_names=["aileron", "elevator", "rudder", "throttle"],
        fps=10,
        obs_stats=stats,
        action_stats={"mean": np.zeros(4), "std": np.ones(4)},
    )


def test_histories_and_chunks_stay_inside_their_stretch():
    # episode 0: frames 0-3; episode 1: frames 0-1, then a gap (a takeover), frames 5-6
    frames = frames_of([0, 0, 0, 0, 1, 1, 1, 1], [0, 1, 2, 3, 0, 1, 5, 6])
    window = ChunkConfig(history=3, chunk=3).window
    assert window.observation == (-2, -1, 0) and window.action == (0, 1, 2)
    past, _ = window_indices(frames, window.observation)
    ahead, inside = window_indices(frames, window.action)
    assert past[0].tolist() == [0, 0, 0] and past[3].tolist() == [1, 2, 3]
    assert past[4].tolist() == [4, 4, 4] and past[6].tolist() == [6, 6, 6]  # after the gap
    assert ahead[2].tolist() == [2, 3, 3] and inside[2].tolist() == [True, True, False]
    assert inside[5].tolist() == [True, False, False]  # the gap ends its stretch
    batches = TensorBatches(frames, 8, window=window)
    ((obs, act),) = list(batches)
    assert obs.shape == (8, 3, 2) and act.shape == (8, 3, 4)
    assert int(torch.isnan(act[:, :, 0]).sum()) == int((~inside).sum())


def test_temporal_ensembling_weights_newer_chunks_by_the_decay():
    stats = {"mean": np.zeros(3), "std": np.ones(3)}
    act_stats = {"mean": np.zeros(4), "std": np.ones(4)}
    policy = ChunkPolicy(
        ChunkConfig(hidden=[8], history=2, chunk=3, ensemble_decay=1.0), stats, act_stats
    )
    torch.manual_seed(0)
    obs = [torch.randn(1, 3) for _ in range(3)]
    state, chunks = None, []
    history = obs[0].unsqueeze(1).repeat(1, 2, 1)
    for step, o in enumerate(obs):
        if step:
            history = torch.cat([history[:, 1:], o.unsqueeze(1)], 1)
        chunks.append(policy.forward(history)[0])
        action, state = policy.act(o, state)
    # at step 2: chunk 0 (age 2) entry 2, chunk 1 (age 1) entry 1, chunk 2 (age 0) entry 0
    w = np.exp(-np.array([2.0, 1.0, 0.0]))
    expected = sum(wi * c[2 - j] for j, (wi, c) in enumerate(zip(w, chunks, strict=True))) / w.sum()
    assert torch.allclose(action[0], expected, atol=1e-6)


@pytest.mark.slow
def test_chunk_policy_trains_and_flies(tiny_dataset, tmp_path, far_target_seeds):
    result = train_bc(
        TrainConfig(
            dataset=tiny_dataset,
            out=tmp_path,
            policy=ChunkConfig(hidden=[64], history=3, chunk=5),
            epochs=10,
        )
    )
    assert result.train_loss[-1] < 0.6 * result.train_loss[0]
    assert result.meta["train"]["policy"] == "chunk"
    agent = PolicyAgent.load(tmp_path)
    assert agent.policy.config == ChunkConfig(hidden=[64], history=3, chunk=5)
    env = AircraftEnv("altitude", "c172p", episode_time_s=60)
    zero = ConstantAgent((0.0, 0.0, 0.0, env.aircraft.profile.cruise_throttle))
    (seed,) = far_target_seeds(env, 1)
    learned = trace_of(Rollout(env, [agent]).episode(seed))
    baseline = trace_of(Rollout(env, [zero]).episode(seed))
    assert np.isfinite(learned.actions).all() and not learned.terminated
    assert learned.total_return > baseline.total_return + 50


def test_chunk_config_rejects_nonsense():
    with pytest.raises(Exception, match="history=0"):
        ChunkConfig(history=0)
    with pytest.raises(Exception, match="ensemble_decay"):
        ChunkConfig(ensemble_decay=float("nan"))
