"""`train bc`'s command line: the policy's settings are flags of their own, with the names,
defaults and meanings they always had, built from the registered policy configurations."""

from pathlib import Path

import pytest

from gymfg_il import cli, train
from gymfg_il.learning.config import TrainConfig
from gymfg_il.policies.configuration_chunk import ChunkConfig
from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.configuration_vision import VisionConfig


def parsed(*flags):
    args = train.build_parser().parse_args(["bc", *flags])
    return cli.build(TrainConfig, args, policy=train.policy_config(args))


@pytest.mark.parametrize(
    "flags, policy",
    [
        ([], MLPConfig(hidden=[256, 256])),
        (["--hidden", "64", "32"], MLPConfig(hidden=[64, 32])),
        (["--policy", "gru"], GRUConfig(hidden=256, sequence_length=32)),
        (["--policy", "gru", "--hidden", "64", "64", "--sequence-length", "8"],
         GRUConfig(hidden=64, sequence_length=8)),  # a GRU's width: the first value
        (["--policy", "chunk", "--history", "2", "--chunk", "3"], ChunkConfig(history=2, chunk=3)),
        (["--policy", "vision", "--camera", "chase", "--frames", "3", "--hidden", "64"],
         VisionConfig(camera="chase", frames=3, hidden=[64])),
    ],
)  # fmt: skip
def test_policy_flags_set_the_policys_own_settings(flags, policy):
    assert parsed(*flags).policy == policy


def test_the_runs_flags_keep_their_defaults():
    cfg = parsed()
    assert (cfg.epochs, cfg.batch_size, cfg.lr, cfg.weight_decay, cfg.seed) == (
        None, 256, 1e-3, 1e-4, 0
    )  # fmt: skip
    assert (cfg.val_fraction, cfg.device, cfg.obs_noise, cfg.threads) == (0.1, "cpu", 0.0, None)
    assert parsed("--policy", "vision").threads_wanted == 0 and cfg.threads_wanted == 1


def test_a_setting_of_another_policy_type_is_named_and_left_out(capsys):
    assert parsed("--sequence-length", "8").policy == MLPConfig()
    assert "--sequence-length is no setting of a mlp policy" in capsys.readouterr().err


def test_a_bad_setting_is_one_line_naming_it(tmp_path, capsys):
    argv = ["bc", "--policy", "chunk", "--history", "0", "--out", str(tmp_path / "p")]
    assert train.main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: chunk policy: history=0 and chunk=10 must be >= 1"), err


@pytest.mark.parametrize(
    "seconds, text",
    [
        (0.2, "under a second"),
        (42, "about 42 s"),
        (200, "about 3 min 20 s"),
        (3900, "about 1 h 05 min"),
    ],
)
def test_durations_read_as_a_wait(seconds, text):
    assert train.duration(seconds) == text


def test_train_bc_without_out_never_replaces_an_earlier_policy(tmp_path, monkeypatch):
    """#53: `train bc` without --out overwrote the last policy of the same task silently."""
    from gymfg_il import train

    sample = Path(__file__).resolve().parent.parent / "datasets/sample-altitude-c172p/dataset"
    monkeypatch.chdir(tmp_path)
    argv = ["bc", "--dataset", str(sample), "--epochs", "1", "--hidden", "16", "--no-progress"]
    assert train.main(argv) == 0
    first = (tmp_path / "policies/bc-altitude-c172p-mlp/model.safetensors").read_bytes()
    assert train.main([*argv, "--seed", "1"]) == 0
    assert (tmp_path / "policies/bc-altitude-c172p-mlp/model.safetensors").read_bytes() == first
    assert (tmp_path / "policies/bc-altitude-c172p-mlp-2/model.safetensors").is_file()
