"""LeRobot's own tools on our data and in our envs: lerobot-train (ACT) on a dataset from
`collect autopilot`, lerobot-eval in a GymFG env through the plugin, and our eval flying the
LeRobot checkpoint beside the controller."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gymfg_il import collect
from gymfg_il import eval as evaluate

pytestmark = pytest.mark.lerobot
BIN = Path(sys.executable).parent
# a tiny ACT: the test checks the tools meet, not how well it flies
TINY_ACT = [
    "--policy.type=act",
    "--policy.dim_model=32",
    "--policy.n_heads=2",
    "--policy.dim_feedforward=64",
    "--policy.n_encoder_layers=1",
    "--policy.n_decoder_layers=1",
    "--policy.n_vae_encoder_layers=1",
    "--policy.latent_dim=8",
    "--policy.chunk_size=5",
    "--policy.n_action_steps=1",
    '--policy.normalization_mapping={"VISUAL": "MEAN_STD", "STATE": "MEAN_STD", '
    '"ENV": "MEAN_STD", "ACTION": "MEAN_STD"}',
]


def _run(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "HF_LEROBOT_HOME": str(cwd / "hf")}
    done = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return done


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("lerobot") / "roll"
    argv = ["autopilot", "--task", "roll", "--episodes", "3", "--episode-time", "20"]
    assert collect.main([*argv, "--out", str(out), "--no-progress"]) == 0
    return out


@pytest.fixture(scope="module")
def act(session):
    out = session.parent / "act"
    _run(
        [
            str(BIN / "lerobot-train"),
            *TINY_ACT,
            "--dataset.repo_id=gymfg/roll-c172p",
            f"--dataset.root={session / 'dataset'}",
            "--policy.device=cpu",
            "--policy.push_to_hub=false",
            f"--output_dir={out}",
            "--steps=3",
            "--batch_size=4",
            "--save_freq=3",
            "--log_freq=1",
            "--num_workers=0",
        ],
        session.parent,
    )
    return out


def test_datasets_carry_the_task_columns_as_environment_state(session):
    info = json.loads((session / "dataset/meta/info.json").read_text())
    state = info["features"]["observation.state"]
    env_state = info["features"]["observation.environment_state"]
    assert env_state["names"] == ["roll_deg_target", "roll_deg_error", "roll_deg_error_integral"]
    stats = json.loads((session / "dataset/meta/stats.json").read_text())
    assert len(stats["observation.environment_state"]["std"]) == 3

    import pyarrow.parquet as pq

    table = pq.read_table(session / "dataset/data/chunk-000/file-000.parquet")
    obs = np.array(table["observation.state"].to_pylist())
    env = np.array(table["observation.environment_state"].to_pylist())
    columns = [state["names"].index(n) for n in env_state["names"]]
    np.testing.assert_array_equal(env, obs[:, columns])


def test_lerobot_train_act_on_our_dataset(act):
    model = act / "checkpoints/last/pretrained_model"
    config = json.loads((model / "config.json").read_text())
    assert config["type"] == "act"
    assert config["input_features"]["observation.environment_state"]["shape"] == [3]
    assert (model / "model.safetensors").is_file()


def test_lerobot_eval_flies_one_episode_in_gymfg(act):
    out = act.parent / "lerobot-eval"
    _run(
        [
            str(BIN / "lerobot-eval"),
            f"--policy.path={act / 'checkpoints/last/pretrained_model'}",
            "--policy.device=cpu",
            "--env.type=gymfg",
            "--env.discover_packages_path=gymfg_il.lerobot_env",
            "--env.task=roll",
            "--env.aircraft=c172p",
            "--env.episode_time_s=3",
            "--eval.n_episodes=1",
            "--eval.batch_size=1",
            f"--output_dir={out}",
        ],
        act.parent,
    )
    overall = json.loads((out / "eval_info.json").read_text())["overall"]
    assert overall["n_episodes"] == 1
    # 30 steps of ACT's tiny untrained net: a short flight, judged (not the 100 % fallback)
    assert overall["pc_success"] == 0.0
    assert list((out / "videos").rglob("*.mp4"))


def test_our_eval_flies_the_lerobot_checkpoint(act, tmp_path, capsys):
    rows = tmp_path / "rows.json"
    argv = ["--policy", str(act), "--episodes", "1", "--episode-time", "5", "--json", str(rows)]
    assert evaluate.main([*argv, "--no-progress"]) == 0
    found = json.loads(rows.read_text())["rows"]
    assert [r["agent"] for r in found] == ["controller", "policy:act"]
    # its flight is its dataset's: roll on the c172p at 10 Hz
    assert found[1]["task"] == "roll" and found[1]["aircraft"] == "c172p"
    assert found[1]["episodes"] == 1 and np.isfinite(found[1]["mean_return"])


def test_a_lerobot_checkpoint_on_the_wrong_task_is_a_clear_error(act, capsys):
    argv = ["--policy", str(act), "--task", "approach", "--episodes", "1", "--no-progress"]
    assert evaluate.main(argv) == 2
    err = capsys.readouterr().err
    assert "observation.state" in err and "--task" in err


def test_an_unrecognised_policy_folder_is_a_clear_error(tmp_path, capsys):
    (tmp_path / "config.json").write_text(json.dumps({"hello": 1}))
    (tmp_path / "model.safetensors").write_bytes(b"")
    assert evaluate.main(["--policy", str(tmp_path), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "lerobot-train" in err and "Traceback" not in err


def test_a_checkpoint_without_its_dataset_needs_task_and_aircraft(act, tmp_path, capsys):
    moved = tmp_path / "act"
    shutil.copytree(act / "checkpoints/last/pretrained_model", moved)
    train = json.loads((moved / "train_config.json").read_text())
    train["dataset"]["root"] = str(tmp_path / "gone")
    (moved / "train_config.json").write_text(json.dumps(train))
    assert evaluate.main(["--policy", str(moved), "--episodes", "1", "--no-progress"]) == 2
    assert "--task and --aircraft" in capsys.readouterr().err
    argv = ["--policy", str(moved), "--task", "roll", "--aircraft", "c172p", "--episodes", "1"]
    assert evaluate.main([*argv, "--episode-time", "3", "--no-progress"]) == 0


def test_collect_repair_restores_what_lerobot_edit_dataset_dropped(session, tmp_path, capsys):
    from gymfg_il.datasets import lerobot_api as lr

    edited = tmp_path / "edited"
    _run(
        [
            str(BIN / "lerobot-edit-dataset"),
            "--repo_id=gymfg/roll-c172p",
            f"--root={session / 'dataset'}",
            "--new_repo_id=gymfg/roll-edited",
            f"--new_root={edited}",
            "--operation.type=delete_episodes",
            "--operation.episode_indices=[1]",
        ],
        tmp_path,
    )
    columns = lr.open_metadata(edited).episodes.column_names
    assert not [c for c in columns if c.startswith("gymfg/")]  # what LeRobot's edit does
    assert collect.main(["repair", str(edited)]) == 2  # which source: a clear error
    assert "--source" in capsys.readouterr().err
    assert collect.main(["repair", str(edited), "--source", str(session)]) == 0
    restored = lr.open_metadata(edited).episodes
    assert list(restored["gymfg/seed"]) == [1000, 1002]
    assert list(restored["gymfg/log_episode"]) == [0, 2]
    assert list(restored["gymfg/task"]) == ["roll", "roll"]


def test_collect_repair_writes_the_card_a_merge_leaves_out(session, tmp_path, capsys):
    other = tmp_path / "other"
    argv = ["autopilot", "--task", "roll", "--episodes", "1", "--episode-time", "20"]
    assert collect.main([*argv, "--seed", "2000", "--out", str(other), "--no-progress"]) == 0
    merged = tmp_path / "merged"
    roots = json.dumps([str(session / "dataset"), str(other / "dataset")])
    _run(
        [
            str(BIN / "lerobot-edit-dataset"),
            "--new_repo_id=gymfg/roll-merged",
            f"--new_root={merged}",
            "--operation.type=merge",
            '--operation.repo_ids=["gymfg/roll-c172p", "gymfg/roll-other"]',
            f"--operation.roots={roots}",
        ],
        tmp_path,
    )
    assert not (merged / "README.md").exists()  # what LeRobot's merge does
    capsys.readouterr()
    assert collect.main(["repair", str(merged)]) == 0
    assert f"wrote its card {merged / 'README.md'} (none was there)" in capsys.readouterr().out
    card = (merged / "README.md").read_text()
    assert "| episodes | 4 (800 frames) |" in card
    assert "| sources | autopilot (4 episodes) |" in card
    assert collect.main(["repair", str(merged)]) == 0  # a current card is left alone
    assert "its card is current; nothing to repair" in capsys.readouterr().out
