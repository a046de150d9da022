"""The vision policy: an eye (a CNN over the camera) and hands (an MLP over what the eye
estimates and the task's targets), trained on a camera dataset and flown with the env's
camera."""

import numpy as np
import pytest
import torch

from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.learning.bc import TrainConfig, train_bc
from gymfg_il.learning.data import TensorBatches, load_frames
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration_vision import VisionConfig
from gymfg_il.policies.modeling_vision import VisionPolicy, pool_frames
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout


@pytest.fixture(scope="module")
def roll_images(tmp_path_factory):
    out = tmp_path_factory.mktemp("roll-images")
    cfg = CollectConfig(task="roll", episodes=4, episode_time_s=20, out=out, images=["front"])
    collect_autopilot(cfg)
    return out / "dataset"


def test_batches_stack_each_frame_with_the_one_before_inside_its_episode(roll_images):
    frames = load_frames(roll_images, camera="front")
    assert frames.images.shape == (800, 128, 128, 3) and frames.camera == "front"
    batches = TensorBatches(frames, 64, stack=2, pool=2, seed=1)
    (images, obs), act = next(iter(batches))
    assert images.shape == (64, 2, 64, 64, 3) and images.dtype == torch.uint8
    assert obs.shape == (64, 13) and act.shape == (64, 4)
    pooled = pool_frames(torch.as_tensor(frames.images), 2)
    # each stack is (previous frame, frame), the first frame of an episode repeated
    starts = np.flatnonzero(frames.frame == 0)
    for k, i in ((0, starts[1]), (1, starts[1] + 5)):
        want = torch.stack([pooled[max(i - 1, starts[1])], pooled[i]])
        assert torch.equal(batches.images[batches.past[i]], want), k


def test_a_vision_policy_trains_and_flies_by_the_envs_camera(roll_images, tmp_path):
    cfg = TrainConfig(
        dataset=roll_images, out=tmp_path, policy="vision", epochs=3, hidden=[64], threads=2
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
             "roll_deg_error_integral", "heading_deg_target", "heading_deg_error"]  # fmt: skip
    cfg = VisionConfig.for_observation(
        names, image_size=16, pool=1, channels=[4], hidden=[8], dt=0.1
    )
    assert cfg.seen_names == ["roll_deg", "heading_deg"] and cfg.angular == [False, True]
    unit = {"mean": np.zeros(len(names)), "std": np.ones(len(names))}
    policy = VisionPolicy(cfg, unit, {"mean": np.zeros(4), "std": np.ones(4)})
    policy.look = lambda images: torch.tensor([[10.0, 350.0]])  # the eye reads these
    flown = []
    policy.fly = lambda obs: (flown.append(obs.clone()), torch.zeros(1, 4))[1]
    # the observation's own state, errors and integral are truth the policy must not read
    obs = torch.tensor([[0.0, 0.0, 12.5, 99.0, 99.0, 5.0, 99.0]])
    frame = torch.zeros(1, 16, 16, 3, dtype=torch.uint8)
    _, state = policy.act((frame, obs))
    _, state = policy.act((frame, obs), state)
    seen = flown[-1][0]
    assert seen[0] == 10.0 and seen[1] == 350.0  # the estimates
    assert seen[3] == pytest.approx(2.5)  # roll error: target 12.5 less the estimate 10
    assert seen[6] == pytest.approx(15.0)  # heading error wraps: 5 - 350 is +15
    assert seen[4] == pytest.approx(2 * 2.5 * 0.1)  # two steps of the error, times dt
    assert seen[2] == 12.5 and seen[5] == 5.0  # targets are read as they are
