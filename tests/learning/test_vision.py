"""The vision policy: an eye (a CNN over the camera) and hands (an MLP over what the eye
estimates and the task's targets), trained on a camera dataset and flown with the env's
camera."""

import math

import numpy as np
import pytest
import torch

from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.learning.batches import TensorBatches
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.data import load_frames
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration_vision import VisionConfig
from gymfg_il.policies.modeling_vision import VisionPolicy
from gymfg_il.policies.window import pool_frames
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.library import TASK_FAMILIES, task_class


@pytest.fixture(scope="module")
def roll_images(tmp_path_factory):
    out = tmp_path_factory.mktemp("roll-images")
    cfg = CollectConfig(task="roll", episodes=4, episode_time_s=20, out=out, images=["front"])
    collect_autopilot(cfg)
    return out / "dataset"


def test_batches_stack_each_frame_with_the_one_before_inside_its_episode(roll_images):
    frames = load_frames(roll_images, camera="front")
    assert frames.images.shape == (800, 128, 128, 3) and frames.camera == "front"
    window = VisionConfig(frames=2, pool=2).window
    assert window.images == (-1, 0) and window.camera == "front" and window.pool == 2
    batches = TensorBatches(frames, 64, seed=1, window=window)
    (images, obs), act = next(iter(batches))
    assert images.shape == (64, 2, 64, 64, 3) and images.dtype == torch.uint8
    assert obs.shape == (64, 13) and act.shape == (64, 4)
    pooled = pool_frames(torch.as_tensor(frames.images), 2)
    # each stack is (previous frame, frame), the first frame of an episode repeated
    starts = np.flatnonzero(frames.frame == 0)
    for k, i in ((0, starts[1]), (1, starts[1] + 5)):
        want = torch.stack([pooled[max(i - 1, starts[1])], pooled[i]])
        assert torch.equal(batches.images[batches.index["images"][i]], want), k


@pytest.mark.slow
def test_a_vision_policy_trains_and_flies_by_the_envs_camera(roll_images, tmp_path):
    cfg = TrainConfig(
        dataset=roll_images, out=tmp_path, policy=VisionConfig(hidden=[64]), epochs=3, threads=2
    )
    result = train_bc(cfg)
    assert result.train_loss[-1] < result.train_loss[0]
    assert result.meta["camera"] == {"view": "front", "size": 128}
    policy_cfg = result.meta["train"]
    assert policy_cfg["policy"] == "vision"
    agent = PolicyAgent.load(tmp_path)
    config = agent.policy.config
    assert config.target_names == ["roll_deg_target"]
    assert config.error_names == ["roll_deg_error"]
    assert config.integral_names == ["roll_deg_error_integral"]
    assert "roll_deg" in config.seen_names and "altitude_ft" in config.seen_names
    assert not any(n.endswith(("_target", "_error", "_integral")) for n in config.seen_names)
    # the hands learned with the eye's running error added to what it estimates
    assert (agent.policy.eye_error > 0).all()
    with pytest.raises(ConfigError, match="camera"):
        agent.act(np.zeros(13, np.float32))  # outside an env it has no eyes
    from gymfg_il.envs.single import AircraftEnv

    env = AircraftEnv("roll", "c172p", episode_time_s=5)
    flown = AgentSpec.policy(tmp_path).make(env)
    trace = trace_of(Rollout(env, [flown]).episode(3))
    assert len(trace.actions) == 50 and np.isfinite(trace.actions).all()


def test_pooling_is_the_block_mean_and_the_config_checks_its_sizes():
    frames = torch.arange(4 * 4 * 3, dtype=torch.uint8).reshape(1, 4, 4, 3)
    pooled = pool_frames(frames, 2)
    assert pooled.shape == (1, 2, 2, 3)
    assert int(pooled[0, 0, 0, 0]) == round((0 + 3 + 12 + 15) / 4)
    with pytest.raises(ConfigError, match="leaves nothing"):
        VisionConfig(image_size=32, pool=4, channels=[8, 8, 8, 8])
    with pytest.raises(ConfigError, match="camera"):
        VisionConfig(camera="cockpit")


def test_in_flight_errors_and_integrals_come_from_the_eyes_estimates():
    names = ["roll_deg", "heading_deg", "roll_deg_target", "roll_deg_error",
             "roll_deg_error_integral", "heading_deg_target", "heading_deg_error",
             "altitude_ft_error", "turn_remaining_deg"]  # fmt: skip
    high = [180.0, 360.0, 180.0, 180.0, 0.6, 360.0, 180.0, 1e4, 360.0]
    cfg = VisionConfig.for_observation(
        names, high, image_size=16, pool=1, channels=[4], hidden=[8], dt=0.1
    )
    assert cfg.seen_names == ["roll_deg"] and cfg.integral_limit == [0.6]
    assert cfg.target_names == ["roll_deg_target", "heading_deg_target"]
    # the compass, an error to a target the task does not observe, and its bookkeeping
    assert cfg.given_names == [
        "heading_deg", "heading_deg_error", "altitude_ft_error", "turn_remaining_deg"
    ]  # fmt: skip
    unit = {"mean": np.zeros(len(names)), "std": np.ones(len(names))}
    policy = VisionPolicy(cfg, unit, {"mean": np.zeros(4), "std": np.ones(4)})
    policy.look = lambda images: torch.tensor([[10.0]])  # the eye reads a roll of 10
    flown = []
    policy.fly = lambda obs: (flown.append(obs.clone()), torch.zeros(1, 4))[1]
    # the observation's own roll, its error and integral are truth the policy must not read
    obs = torch.tensor([[0.0, 350.0, 12.5, 99.0, 99.0, 5.0, 15.0, -42.0, 90.0]])
    frame = torch.zeros(1, 16, 16, 3, dtype=torch.uint8)
    _, state = policy.act((frame, obs))
    _, state = policy.act((frame, obs), state)
    seen = flown[-1][0]
    assert seen[0] == 10.0  # the estimate
    assert seen[3] == pytest.approx(2.5)  # roll error: target 12.5 less the estimate 10
    assert seen[4] == pytest.approx(2 * 2.5 * 0.1)  # two steps of the error, times dt
    assert seen[2] == 12.5 and seen[5] == 5.0  # targets are read as they are
    assert seen[[1, 6, 7, 8]].tolist() == [350.0, 15.0, -42.0, 90.0]  # so is what is given
    for _ in range(3):  # the integral saturates where the task's does (0.6 here)
        _, state = policy.act((frame, obs), state)
    assert flown[-1][0][4] == pytest.approx(0.6)


@pytest.mark.parametrize("family", sorted(TASK_FAMILIES))
def test_a_vision_policy_reads_every_entry_a_task_observes(family):
    """Seen, a target, recomputed, or given: no observation entry is left out of the hands'
    inputs, and only the aircraft's own state is left to the eye."""
    task = task_class(family)()
    names = list(task.observation_names)
    cfg = VisionConfig.for_observation(names, [float(v) for v in task.observation_bounds()[1]])
    parts = [cfg.seen_names, cfg.target_names, cfg.error_names, cfg.integral_names,
             cfg.given_names]  # fmt: skip
    assert sorted(n for part in parts for n in part) == sorted(names)
    assert all(n in INDEX for n in cfg.seen_names)
    assert all(0 < v < math.inf for v in cfg.integral_limit)
