"""Checkpoints written before the policy registry load as they did: config.json keeps its
layout (``type``, ``policy`` with every setting, the statistics, what the run recorded), and
DAgger retrains such a policy with the settings it was trained with."""

import json

import numpy as np
import pytest

from gymfg_il.learning.dagger import retrain_config
from gymfg_il.policies.checkpoint import load_policy, save_policy
from gymfg_il.policies.configuration_chunk import ChunkConfig
from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.configuration_vision import VisionConfig
from gymfg_il.policies.factory import make_policy, policy_type

# config.json's "policy" as `train bc` wrote it before the registry (one of each type)
WRITTEN = [
    ({"type": "mlp", "hidden": [32, 32], "dropout": 0.0}, MLPConfig(hidden=[32, 32])),
    ({"type": "gru", "hidden": 32, "layers": 1, "sequence_length": 8},
     GRUConfig(hidden=32, sequence_length=8)),
    ({"type": "chunk", "hidden": [32, 32], "history": 4, "chunk": 10, "ensemble_decay": 0.5},
     ChunkConfig(hidden=[32, 32])),
    ({"type": "vision", "camera": "front", "image_size": 64, "frames": 2, "pool": 2,
      "channels": [16, 32, 32, 32], "hidden": [256, 256], "seen_names": ["roll_deg"],
      "seen_index": [0], "target_names": ["roll_deg_target"], "target_index": [1],
      "error_names": ["roll_deg_error"], "error_index": [2], "error_seen": [0],
      "error_target": [0], "integral_names": ["roll_deg_error_integral"],
      "integral_index": [3], "integral_error": [0], "integral_limit": [21600.0],
      "given_names": [], "given_index": [], "aux_weight": 1.0, "roll_augment_deg": 15.0,
      "augment_share": 0.5, "noise_scale": 1.0, "dt": 0.1},
     VisionConfig.for_observation(
         ["roll_deg", "roll_deg_target", "roll_deg_error", "roll_deg_error_integral"],
         [180.0, 180.0, 180.0, 21600.0], image_size=64)),
]  # fmt: skip

# a run's "train" as written then: the policy's settings flat beside the run's
OLD_TRAIN = {
    "dataset": "datasets/sample-altitude-c172p/dataset", "out": "policies/p", "policy": "gru",
    "epochs": 7, "batch_size": 128, "lr": 0.002, "weight_decay": 0.0001, "seed": 3,
    "val_fraction": 0.1, "device": "cpu", "hidden": [32, 32], "sequence_length": 8,
    "history": 4, "chunk": 10, "camera": "front", "frames": 2, "obs_noise": 0.0,
    "mixed_tasks": False, "threads": None, "train_frames": 16200, "val_frames": 1800,
    "seconds": 0.5,
}  # fmt: skip


@pytest.mark.parametrize(("written", "config"), WRITTEN, ids=[w["type"] for w, _ in WRITTEN])
def test_a_policy_written_before_loads_with_its_settings(written, config, tmp_path):
    assert policy_type(written["type"]).config.from_dict(written) == config
    assert config.to_dict() == written  # and is written the same way
    n_obs = len(written.get("seen_names", [])) + 3 if written["type"] == "vision" else 5
    obs = {"mean": np.zeros(n_obs), "std": np.ones(n_obs)}
    act = {"mean": np.zeros(4), "std": np.ones(4)}
    save_policy(make_policy(config, obs, act), tmp_path, {"name": "p"}, obs, act)
    saved = json.loads((tmp_path / "config.json").read_text())
    assert saved["type"] == written["type"] and saved["policy"] == written
    policy, meta = load_policy(tmp_path)
    assert policy.config == config and meta["name"] == "p"


def test_dagger_retrains_an_old_policy_with_its_own_settings(tmp_path):
    meta = {"type": "gru", "policy": WRITTEN[1][0], "train": OLD_TRAIN}
    cfg = retrain_config(meta, tmp_path / "dataset", tmp_path / "p1", {"epochs": 2})
    assert cfg.policy == GRUConfig(hidden=32, sequence_length=8)
    assert (cfg.epochs, cfg.batch_size, cfg.lr, cfg.seed) == (2, 128, 0.002, 3)
    assert cfg.dataset == tmp_path / "dataset" and cfg.out == tmp_path / "p1"
