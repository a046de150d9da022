import json
import math

import numpy as np
import pytest

from gymfg_il.agent import ConstantAgent
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.learning.batches import TensorBatches
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.data import load_frames, split_by_episode
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.factory import make_config
from gymfg_il.rollout import Rollout


def fly_episode(env, agent, seed):
    return trace_of(Rollout(env, [agent]).episode(seed))


def cfg_like(dataset, out):
    """The module's training run: one of the tiny dataset's six episodes held out."""
    return TrainConfig(dataset=dataset, out=out, epochs=25, seed=3, val_fraction=0.17)


@pytest.fixture(scope="module")
def trained(tiny_dataset, tmp_path_factory):
    return train_bc(cfg_like(tiny_dataset, tmp_path_factory.mktemp("policy")))


def test_loss_falls_and_checkpoint_is_complete(trained):
    assert trained.train_loss[-1] < 0.5 * trained.train_loss[0]
    assert trained.val_loss[-1] < trained.val_loss[0]
    for name in ("config.json", "model.safetensors", "loss.png", "train_log.json"):
        assert (trained.out / name).is_file()
    meta = json.loads((trained.out / "config.json").read_text())
    assert meta["task"] == "altitude" and meta["aircraft"] == "c172p" and meta["type"] == "mlp"
    remembered = [*meta["observation_names"], *meta["memory_names"]]  # the memory: the policy's
    assert len(meta["obs_stats"]["mean"]) == len(remembered) == len(meta["observation_names"]) + 2


def test_training_is_reproducible_with_a_seed(trained, tiny_dataset, tmp_path):
    again = train_bc(cfg_like(tiny_dataset, tmp_path))
    assert again.train_loss == trained.train_loss
    assert (tmp_path / "model.safetensors").read_bytes() == (
        trained.out / "model.safetensors"
    ).read_bytes()


@pytest.mark.slow
def test_policy_flies_better_than_a_zero_action_agent(trained, far_target_seeds):
    env = AircraftEnv("altitude", "c172p", episode_time_s=60)
    policy = PolicyAgent.load(trained.out)
    zero = ConstantAgent((0.0, 0.0, 0.0, env.aircraft.profile.cruise_throttle))
    for seed in far_target_seeds(env, 2):
        learned = fly_episode(env, policy, seed)
        baseline = fly_episode(env, zero, seed)
        assert learned.total_return > baseline.total_return + 50
        assert abs(learned.error[-1]) < abs(baseline.error[-1])


def test_gru_policy_trains_and_flies(tiny_dataset, tmp_path):
    result = train_bc(
        TrainConfig(
            dataset=tiny_dataset,
            out=tmp_path,
            policy=GRUConfig(hidden=32, sequence_length=8),
            epochs=4,
        )
    )
    assert result.train_loss[-1] < result.train_loss[0]
    agent = PolicyAgent.load(tmp_path)
    env = AircraftEnv("altitude", "c172p", episode_time_s=5)
    ep = fly_episode(env, agent, 0)
    assert len(ep.rewards) == 50 and np.isfinite(ep.actions).all()


def test_batches_and_split(tiny_dataset):
    frames = load_frames(tiny_dataset)
    assert frames.obs.shape == (1800, len(frames.observation_names)) and frames.fps == 10
    train, val = split_by_episode(frames, 0.34, seed=0)
    assert val is not None
    assert not set(np.unique(train.episode)) & set(np.unique(val.episode))
    windows = TensorBatches(train, 64, seed=0, window=GRUConfig(sequence_length=16).window)
    seen = 0
    for obs, act in windows:
        assert obs.shape[1:] == (16, frames.obs.shape[1]) and act.shape[1:] == (16, 4)
        seen += len(obs)
    assert seen == len(windows.starts)
    ep = train.episode
    starts = windows.starts.numpy()
    assert (ep[starts] == ep[starts + 15]).all()  # no window crosses an episode boundary


def test_the_split_holds_out_its_share_of_the_episodes_and_none_below_one(tiny_dataset):
    # six episodes: 10 % of them is under one, so all six train (five demonstrations at the
    # default 0.1 train on all five, not on four)
    frames = load_frames(tiny_dataset)
    train, val = split_by_episode(frames, 0.1, seed=0)
    assert val is None and train is frames
    for fraction, held in ((0.17, 1), (0.5, 3), (0.99, 5), (1 - 1e-12, 5)):  # one trains
        train, val = split_by_episode(frames, fraction, seed=0)
        assert val is not None and len(np.unique(val.episode)) == held
        assert len(np.unique(train.episode)) == 6 - held


def test_a_run_with_no_episode_held_out_writes_json_every_reader_parses(tiny_dataset, tmp_path):
    # six episodes at the default 0.1: none held out, so no validation loss, written as null
    result = train_bc(TrainConfig(dataset=tiny_dataset, out=tmp_path, epochs=1))
    assert math.isnan(result.val_loss[-1])

    def refuse(constant):
        raise AssertionError(f"{constant} is not JSON")

    for name in ("config.json", "train_log.json"):
        text = (tmp_path / name).read_text()
        found = json.loads(text, parse_constant=refuse)
        log = found["train"] if name == "config.json" else found
        assert log["val_loss"] == [None] and math.isfinite(log["train_loss"][0])


def test_human_gated_episodes_teach_only_their_takeovers(tiny_dataset):
    frames = load_frames(tiny_dataset)
    assert frames.intervention is not None and not frames.intervention.any()
    assert frames.demonstrated() is frames  # demonstrations are kept whole
    # episode 1 becomes a policy flight a person watched, taking over for 20 frames
    sources = list(frames.episodes["gymfg/source"])
    sources[1] = "policy+synthetic"
    frames.episodes = {**frames.episodes, "gymfg/source": sources}
    frames.intervention = frames.intervention.copy()
    took = np.flatnonzero(frames.episode == 1)[100:120]
    frames.intervention[took] = True
    kept = frames.demonstrated()
    assert len(kept) == len(frames) - (frames.episode == 1).sum() + 20
    assert (kept.frame[kept.episode == 1] == frames.frame[took]).all()
    # a GRU window never spans the gaps the policy's own frames leave
    windows = TensorBatches(kept, 8, seed=0, window=GRUConfig(sequence_length=10).window)
    starts = windows.starts.numpy()
    assert (kept.frame[starts + 9] - kept.frame[starts] == 9).all()
    assert (kept.episode[starts] == 1).sum() == 20 - 9


def test_bad_training_inputs(tmp_path):
    with pytest.raises(ConfigError, match="no LeRobot dataset"):
        train_bc(TrainConfig(dataset=tmp_path / "missing", epochs=1))
    with pytest.raises(ConfigError, match="policy='transformer'"):
        TrainConfig(policy="transformer")
    with pytest.raises(ConfigError, match="unknown policy 'transformer'; choose one of mlp"):
        make_config("transformer")
    with pytest.raises(ConfigError, match="sequence_length=1 must be >= 2"):
        make_config("gru", sequence_length=1)
    with pytest.raises(ConfigError, match="2 problems"):
        TrainConfig(lr=-1, val_fraction=1.5)


def test_policy_refuses_the_wrong_task(trained):
    agent = PolicyAgent.load(trained.out)
    with pytest.raises(ConfigError, match="trained on"):
        agent.check_observation(AircraftEnv("heading", "c172p").observation_names)
    with pytest.raises(ConfigError, match="not a policy checkpoint"):
        PolicyAgent.load(trained.out.parent / "nothing-here")


def test_default_epochs_follow_who_demonstrated(tiny_dataset):
    from gymfg_il.learning.config import EPOCHS_AUTOPILOT, EPOCHS_PERSON, default_epochs

    frames = load_frames(tiny_dataset)
    assert default_epochs(frames) == EPOCHS_AUTOPILOT == 60
    for person in ("synthetic", "human", "policy+human"):
        sources = list(frames.episodes["gymfg/source"])
        sources[2] = person
        frames.episodes = {**frames.episodes, "gymfg/source": sources}
        assert default_epochs(frames) == EPOCHS_PERSON == 20


def test_demonstrations_flown_in_two_weathers_train_a_policy_of_the_first_ones_flight(
    tmp_path, caplog
):
    # a person adds gusty flights (or the autopilot turbulent ones) to the calm ones already
    # there: one dataset, and the policy still records the flight it flies by default
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.collectors.config import CollectConfig

    calm = CollectConfig(task="heading", episodes=2, episode_time_s=3, out=tmp_path / "s")
    collect_autopilot(calm)
    caplog.set_level("INFO", logger="gymfg_il.collectors.session")
    rough = CollectConfig(
        task="heading", episodes=1, episode_time_s=3, seed=1100, turbulence="moderate",
        out=tmp_path / "s",
    )  # fmt: skip
    collect_autopilot(rough)
    assert "another flight" not in caplog.text and "in other weather" in caplog.text
    result = train_bc(TrainConfig(dataset=tmp_path / "s" / "dataset", out=tmp_path / "p", epochs=1))
    meta = json.loads((result.out / "config.json").read_text())
    assert meta["spec"]["turbulence"] == "none" and meta["task"] == "heading"
    assert "2 weathers" in meta["spec_note"]
    caplog.clear()
    jet = CollectConfig(
        task="heading", aircraft="f15", episodes=1, episode_time_s=3, seed=1200,
        out=tmp_path / "s",
    )  # fmt: skip
    collect_autopilot(jet)  # another aircraft is another flight, as before
    assert "another flight" in caplog.text
