"""Hostile and broken inputs to loading checkpoints and to `train bc` (red team, issue 32):
a checkpoint never makes GymFG import or call what its files name, training never saves a
policy from non-finite data, a killed save leaves the whole old policy or the whole new
one, and a damaged dataset is one line "error: ..." with exit status 2."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from gymfg_il import eval as evaluate
from gymfg_il import train
from gymfg_il.policies.lerobot_allowed import UnsafeCheckpointError
from gymfg_il.policies.lerobot_checkpoint import LeRobotAgent

SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    for needle in needles:
        assert needle in err, err


@pytest.fixture(scope="module")
def act_checkpoint(tmp_path_factory):
    """A real tiny ACT ``pretrained_model`` folder, saved by LeRobot's own code as
    lerobot-train saves one (config, weights, pre- and post-processor with statistics), for
    the altitude task's 13 observations and its 3 task columns."""
    import torch
    from lerobot.configs.types import FeatureType, PolicyFeature
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.act.modeling_act import ACTPolicy
    from lerobot.policies.factory import make_pre_post_processors

    shapes = {"observation.state": 13, "observation.environment_state": 3, "action": 4}
    cfg = ACTConfig(
        input_features={
            "observation.state": PolicyFeature(FeatureType.STATE, (13,)),
            "observation.environment_state": PolicyFeature(FeatureType.ENV, (3,)),
        },
        output_features={"action": PolicyFeature(FeatureType.ACTION, (4,))},
        dim_model=32,
        n_heads=2,
        dim_feedforward=64,
        n_encoder_layers=1,
        n_decoder_layers=1,
        n_vae_encoder_layers=1,
        latent_dim=8,
        chunk_size=5,
        n_action_steps=1,
        device="cpu",
        push_to_hub=False,
    )
    stats = {k: {"mean": torch.zeros(n), "std": torch.ones(n)} for k, n in shapes.items()}
    pre, post = make_pre_post_processors(cfg, dataset_stats=stats)
    out = tmp_path_factory.mktemp("act") / "pretrained_model"
    for part in (ACTPolicy(cfg), pre, post):
        part.save_pretrained(out)
    return out


def hostile(act_checkpoint, tmp_path, file, change):
    """A copy of the checkpoint with ``change`` applied to the JSON of ``file``."""
    folder = tmp_path / "pretrained_model"
    shutil.copytree(act_checkpoint, folder)
    data = json.loads((folder / file).read_text())
    change(data)
    (folder / file).write_text(json.dumps(data))
    return folder


def test_a_clean_lerobot_checkpoint_loads_and_acts(act_checkpoint):
    import numpy as np

    info = json.loads((SAMPLE / "meta/info.json").read_text())
    agent = LeRobotAgent(act_checkpoint)
    agent.check_observation(info["features"]["observation.state"]["names"])
    action = agent.act(np.zeros(13))
    assert action.shape == (4,) and np.isfinite(action).all()


@pytest.mark.parametrize("file", ["policy_preprocessor.json", "policy_postprocessor.json"])
def test_a_processor_step_naming_a_class_is_refused_before_it_runs(act_checkpoint, tmp_path, file):
    marker = tmp_path / "ran"
    step = {"class": "subprocess.Popen", "config": {"args": ["sh", "-c", f"touch {marker}"]}}
    folder = hostile(act_checkpoint, tmp_path, file, lambda d: d["steps"].append(step))
    with pytest.raises(UnsafeCheckpointError, match=r"names class 'subprocess\.Popen'") as err:
        LeRobotAgent(folder)
    assert file in str(err.value)
    assert not marker.exists()


def test_eval_refuses_the_hostile_step_in_one_line(act_checkpoint, tmp_path, capsys):
    marker = tmp_path / "ran"
    step = {"class": "os.system", "config": {"command": f"touch {marker}"}}
    folder = hostile(
        act_checkpoint, tmp_path, "policy_preprocessor.json", lambda d: d["steps"].insert(0, step)
    )
    argv = ["--policy", str(folder), "--task", "altitude", "--aircraft", "c172p"]
    argv += ["--episodes", "1", "--no-progress"]
    assert evaluate.main(argv) == 2
    one_error(capsys, "'os.system'")
    assert not marker.exists()


def state_file(folder):
    return next(p.name for p in folder.glob("*.safetensors") if p.name != "model.safetensors")


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "make",
    [
        pytest.param(os.mkfifo, id="fifo"),
        pytest.param(lambda p: p.symlink_to("/dev/zero"), id="dev-zero"),
        pytest.param(lambda p: p.symlink_to("/dev/urandom"), id="dev-urandom"),
    ],
)
@pytest.mark.parametrize(
    "name",
    [
        "config.json",
        "train_config.json",
        "policy_preprocessor.json",
        "policy_postprocessor.json",
        "model.safetensors",
        state_file,
    ],
)
def test_eval_refuses_a_checkpoint_file_that_is_not_a_file(
    act_checkpoint, tmp_path, capsys, name, make
):
    """#52.7: a FIFO in the place of a checkpoint's file hung eval (its open waits for a
    writer); a link to /dev/zero or /dev/urandom read until memory ran out."""
    folder = tmp_path / "pretrained_model"
    shutil.copytree(act_checkpoint, folder)
    name = name if isinstance(name, str) else name(folder)
    (folder / name).unlink(missing_ok=True)  # lerobot-train writes train_config.json
    make(folder / name)
    argv = ["--policy", str(folder), "--task", "altitude", "--aircraft", "c172p"]
    assert evaluate.main([*argv, "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, f"{folder / name} is ")


@pytest.mark.parametrize(
    "file, change, needle",
    [
        (  # LeRobot's own step, but it loads a tokenizer with trust_remote_code
            "policy_preprocessor.json",
            lambda d: d["steps"].append(
                {
                    "registry_name": "action_tokenizer_processor",
                    "config": {"action_tokenizer_name": "/tmp/x", "trust_remote_code": True},
                }
            ),
            "registry_name 'action_tokenizer_processor'",
        ),
        (
            "policy_postprocessor.json",
            lambda d: d["steps"].append({"registry_name": "made_up_step"}),
            "registry_name 'made_up_step'",
        ),
        (
            "policy_preprocessor.json",
            lambda d: d["steps"][3].update(state_file="../../../etc/passwd"),
            "state_file '../../../etc/passwd'",
        ),
        ("config.json", lambda d: d.update(type="pi0_fast"), "policy type 'pi0_fast'"),
        ("config.json", lambda d: d.update(type="os.system"), "policy type 'os.system'"),
        ("config.json", lambda d: d.update(type=["act"]), "policy type ['act']"),
        (
            "config.json",
            lambda d: d.update(vision_backbone="get_model"),
            "vision_backbone 'get_model'",
        ),
        (  # #52.12: with transformers installed, LeRobot would fetch the tokenizer named
            "policy_preprocessor.json",
            lambda d: d["steps"].append(
                {"registry_name": "tokenizer_processor", "config": {"tokenizer_name": "/tmp/x"}}
            ),
            "tokenizer_name '/tmp/x'",
        ),
        (
            "policy_preprocessor.json",
            lambda d: d["steps"].append(
                {"registry_name": "tokenizer_processor", "config": {"tokenizer_name": "me/tok"}}
            ),
            "tokenizer_name 'me/tok'",
        ),
        (
            "policy_preprocessor.json",
            lambda d: d["steps"].append({"registry_name": "tokenizer_processor", "config": []}),
            "tokenizer_name None",
        ),
        (  # SmolVLA's and multi-task DiT's models fetch these
            "config.json",
            lambda d: d.update(vlm_model_name="me/vlm"),
            "vlm_model_name 'me/vlm'",
        ),
        (
            "config.json",
            lambda d: d.update(text_encoder_name="me/clip"),
            "text_encoder_name 'me/clip'",
        ),
    ],
)
def test_names_outside_lerobots_own_policies_are_refused(
    act_checkpoint, tmp_path, file, change, needle
):
    folder = hostile(act_checkpoint, tmp_path, file, change)
    with pytest.raises(UnsafeCheckpointError) as err:
        LeRobotAgent(folder)
    assert needle in str(err.value)


def test_the_tokenizers_lerobots_own_policies_name_are_let_through(act_checkpoint, tmp_path):
    from gymfg_il.policies.lerobot_allowed import checked_files

    step = {
        "registry_name": "tokenizer_processor",
        "config": {"tokenizer_name": "google/paligemma-3b-pt-224", "max_length": 48},
    }
    folder = hostile(
        act_checkpoint, tmp_path, "policy_preprocessor.json", lambda d: d["steps"].append(step)
    )
    assert "policy_preprocessor.json" in checked_files(folder)


def test_ppo_says_a_lerobot_checkpoint_cannot_be_its_start(act_checkpoint, tmp_path, capsys):
    """#52.12: ``train ppo --init`` of an ACT checkpoint said its config had "no
    input_features"; it has them, and PPO fine-tunes GymFG's own MLP policies only."""
    argv = ["ppo", "--init", str(act_checkpoint), "--out", str(tmp_path / "p"), "--no-progress"]
    assert train.main(argv) == 2
    one_error(capsys, "is a LeRobot checkpoint ('act')", "mlp, ppo", "cannot start from")
    assert not (tmp_path / "p").exists()
    run = tmp_path / "run"  # lerobot-train's output folder: its checkpoint is inside
    shutil.copytree(act_checkpoint, run / "checkpoints/last/pretrained_model")
    argv[2] = str(run)
    assert train.main(argv) == 2
    one_error(capsys, "is a LeRobot checkpoint ('act')")


# --- train bc on damaged or non-finite datasets -------------------------------------------


def damaged(tmp_path, how):
    root = tmp_path / "dataset"
    shutil.copytree(SAMPLE, root)
    how(root)
    return root


def edit_json(path, change):
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def set_value(root, column, row, index, value):
    """One value of one frame in the data file, written back as parquet."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = next((root / "data").rglob("*.parquet"))
    table = pq.read_table(path)
    cells = table.column(column).to_pylist()
    cells[row][index] = value
    at = table.schema.get_field_index(column)
    field = table.schema.field(column)
    pq.write_table(table.set_column(at, field, pa.array(cells, type=field.type)), path)


def drop_column(path, column):
    import pyarrow.parquet as pq

    pq.write_table(pq.read_table(path).drop([column]), path)


def truncate(path):
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 3])


def episodes_table(root):
    return next((root / "meta" / "episodes").rglob("*.parquet"))


def bc(tmp_path, *args):
    out = tmp_path / "p"
    argv = ["bc", "--epochs", "1", "--hidden", "16", "--out", str(out), "--no-progress"]
    return train.main([*argv, *args]), out


@pytest.mark.parametrize(
    "how, needles",
    [
        (lambda r: set_value(r, "observation.state", 5, 2, float("nan")),
         ["episode 0 frame 5", "roll_deg=nan"]),
        (lambda r: set_value(r, "action", 1807, 1, float("inf")),
         ["episode 2 frame 7", "elevator=inf"]),
        (lambda r: edit_json(r / "meta/stats.json",
                             lambda d: d["observation.state"]["std"].__setitem__(2, float("nan"))),
         ["observation.state std of roll_deg is nan"]),
        (lambda r: edit_json(r / "meta/stats.json", lambda d: d["action"].update(mean=[0.0])),
         ["action mean has shape (1,), want (4,)"]),
    ],
)  # fmt: skip
def test_train_refuses_values_that_are_not_numbers(tmp_path, capsys, how, needles):
    root = damaged(tmp_path, how)
    code, out = bc(tmp_path, "--dataset", str(root))
    assert code == 2
    one_error(capsys, *needles)
    assert not out.exists()


@pytest.mark.parametrize(
    "how, needle",
    [
        (lambda r: truncate(episodes_table(r)), "file-000.parquet is not readable parquet"),
        (lambda r: truncate(r / "meta/tasks.parquet"), "tasks.parquet is not readable parquet"),
        (lambda r: edit_json(r / "meta/info.json", lambda d: d.update(fps=0)), "fps=0"),
        (lambda r: edit_json(r / "meta/info.json", lambda d: d.update(fps="10")), "fps='10'"),
        (lambda r: (r / "meta/info.json").write_text("[1, 2]"), "holds a list"),
        (lambda r: edit_json(r / "meta/info.json", lambda d: d.update(features=None)),
         "no 'action' feature"),
        (lambda r: edit_json(r / "meta/info.json", lambda d: d.update(total_episodes=99)),
         "metadata and files disagree"),
        (lambda r: edit_json(r / "meta/info.json", lambda d: d.update(codebase_version="v2.1")),
         "BackwardCompatibilityError"),
        (lambda r: drop_column(episodes_table(r), "length"), "has no 'length' column"),
        (lambda r: drop_column(next((r / "data").rglob("*.parquet")), "action"),
         "column 'action' has missing values"),
        (lambda r: (r / "meta/stats.json").write_text("[]"), "LeRobot cannot read"),
    ],
)  # fmt: skip
def test_train_on_damaged_metadata_is_one_line(tmp_path, capsys, how, needle):
    root = damaged(tmp_path, how)
    code, out = bc(tmp_path, "--dataset", str(root))
    assert code == 2
    one_error(capsys, needle, "collect recover")
    assert not out.exists()


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--lr", "1e308"], "lr=1e+308 must lie in (0, 1]"),
        (["--lr", "0.5", "--weight-decay", "4"], "lr x weight_decay < 1"),
        (["--obs-noise", "nan"], "obs_noise=nan"),
        (["--seed", "-1"], "seed=-1"),
        (["--seed", str(2**70)], f"seed={2**70}"),
    ],
)
def test_train_refuses_settings_that_cannot_train(tmp_path, capsys, args, needle):
    code, out = bc(tmp_path, "--dataset", str(SAMPLE), *args)
    assert code == 2
    one_error(capsys, needle)
    assert not out.exists()


def test_a_run_that_diverges_saves_nothing(tmp_path):
    """A step size inside the bounds that still blows the loss up: the run stops with an
    error at the first non-finite epoch, and nothing is written."""
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig
    from gymfg_il.learning.saving import DivergedError
    from gymfg_il.policies.configuration_mlp import MLPConfig

    cfg = TrainConfig(
        dataset=SAMPLE,
        out=tmp_path / "p",
        epochs=3,
        policy=MLPConfig(hidden=[16]),
        lr=1.0,
        obs_noise=1e300,
    )
    with pytest.raises(DivergedError, match="diverged in epoch 1") as err:
        train_bc(cfg)
    assert "obs_noise=1e+300" in str(err.value)
    assert not (tmp_path / "p").exists()


# --- saving over a policy: the whole old one or the whole new one --------------------------

# Trains on the sample in a child process that SIGKILLs itself at one point of the save:
# ``<module>:<function>:before|after`` (the function stays the real one; the kill comes just
# before or just after it runs).
KILLED_SAVE = """
import importlib, os, signal, sys
where, argv = sys.argv[1], sys.argv[2:]
module, name, when = where.split(":")
mod = importlib.import_module(module)
real = getattr(mod, name)
def dying(*args, **kwargs):
    if when == "before":
        os.kill(os.getpid(), signal.SIGKILL)
    result = real(*args, **kwargs)
    os.kill(os.getpid(), signal.SIGKILL)
    return result
setattr(mod, name, dying)
from gymfg_il import train
train.main(argv)
"""


def train_in_child(where, out, hidden):
    import subprocess
    import sys

    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", str(hidden)]
    argv += ["--out", str(out), "--no-progress"]
    return subprocess.run(
        [sys.executable, "-c", KILLED_SAVE, where, *argv],
        capture_output=True,
        text=True,
        timeout=300,
    )


def policy_files(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir()}


@pytest.fixture(scope="module")
def old_policy(tmp_path_factory):
    out = tmp_path_factory.mktemp("old") / "p"
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", "16"]
    assert train.main([*argv, "--out", str(out), "--no-progress"]) == 0
    return out


@pytest.mark.slow
@pytest.mark.parametrize(
    "where, survivor",
    [
        ("safetensors.torch:save_file:before", "old"),  # config.json written, no weights
        ("safetensors.torch:save_file:after", "old"),  # config and weights, no plot
        ("gymfg_il.learning.saving:plot_losses:after", "old"),  # all but the log
        ("gymfg_il.policies.checkpoint_folder:_swap_in:before", "old"),  # all staged
        ("gymfg_il.policies.checkpoint_folder:_swap_in:after", "new"),  # swapped, not cleaned
    ],
)
def test_a_save_killed_at_any_point_leaves_one_whole_policy(old_policy, tmp_path, where, survivor):
    from gymfg_il.policies.checkpoint import load_policy

    out = tmp_path / "p"
    shutil.copytree(old_policy, out)
    before = policy_files(out)
    done = train_in_child(where, out, hidden=32)
    assert done.returncode == -9, done.stderr[-2000:]
    after = policy_files(out)
    hidden = json.loads(after["config.json"])["policy"]["hidden"]
    if survivor == "old":
        assert after == before
    else:
        assert hidden == [32] and set(after) == set(before)
    load_policy(out)  # config and weights belong together
    # what the kill left beside it goes with the next save, which replaces the policy whole
    assert train.main(["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", "8",
                       "--out", str(out), "--no-progress"]) == 0  # fmt: skip
    assert json.loads((out / "config.json").read_text())["policy"]["hidden"] == [8]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p"]


def test_train_never_replaces_a_folder_that_holds_other_files(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--out", str(out), "--no-progress"]
    assert train.main(argv) == 2
    one_error(capsys, "notes.txt", "give a new or empty folder")
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_without_an_atomic_exchange_the_old_policy_is_renamed_aside_and_back(
    old_policy, tmp_path, monkeypatch
):
    """Where the system cannot swap two folders in one step, the old one is renamed aside
    first; should a kill fall before the new one takes its place, the next save puts it back
    (a process id that has ended marks the folder as left behind)."""
    import subprocess
    import sys

    from gymfg_il.policies import checkpoint_folder

    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)  # fmt: skip
    shutil.copytree(old_policy, tmp_path / f".p.old-{int(ended.stdout)}")
    with pytest.raises(RuntimeError), checkpoint_folder.staged(tmp_path / "p"):
        raise RuntimeError("the save failed")
    assert policy_files(tmp_path / "p") == policy_files(old_policy)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p"]

    monkeypatch.setattr(checkpoint_folder, "_exchange", lambda a, b: False)
    with checkpoint_folder.staged(tmp_path / "p") as folder:
        (folder / "config.json").write_text("{}")
    assert policy_files(tmp_path / "p") == {"config.json": b"{}"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p"]


# --- a record naming a task that cannot be built (red team #52.8) -------------------------

UNFLYABLE = [":AltitudeTask", "__main__:AltitudeTask", "gymfg_il.tasks.base:Task"]


def name_task(root, task):
    """The dataset at ``root`` with every episode's flight spec naming ``task``."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = episodes_table(root)
    table = pq.read_table(path)
    specs = []
    for text in table.column("gymfg/spec").to_pylist():
        spec = json.loads(text)
        spec["teams"][0]["roster"][0]["task"] = task
        specs.append(json.dumps(spec))
    at = table.schema.get_field_index("gymfg/spec")
    pq.write_table(table.set_column(at, table.schema.field(at), pa.array(specs)), path)


@pytest.mark.parametrize("task", UNFLYABLE)
def test_train_refuses_a_dataset_naming_a_task_that_cannot_fly(tmp_path, capsys, task):
    root = damaged(tmp_path, lambda r: name_task(r, task))
    code, out = bc(tmp_path, "--dataset", str(root))
    assert code == 2
    printed = capsys.readouterr()
    # refused before training (it prints "training N epoch(s)" first), in one line
    assert printed.err.startswith("error: ") and printed.err.count("\n") == 1, printed.err
    assert not printed.out
    assert "Traceback" not in printed.err and repr(task) in printed.err
    assert not out.exists()


def unflyable_policy(old_policy, tmp_path, task):
    """A copy of a trained policy whose config.json names ``task``."""
    folder = tmp_path / "unflyable"
    shutil.copytree(old_policy, folder)

    def change(config):
        config["task"] = config["spec"]["teams"][0]["roster"][0]["task"] = task

    edit_json(folder / "config.json", change)
    return folder


@pytest.mark.parametrize("task", [":AltitudeTask", "gymfg_il.tasks.base:Task"])
@pytest.mark.parametrize("entry", ["eval", "ppo --init", "collect dagger"])
def test_flying_a_policy_that_names_a_task_that_cannot_fly_is_one_line(
    old_policy, tmp_path, capsys, entry, task
):
    from gymfg_il import collect

    policy = str(unflyable_policy(old_policy, tmp_path, task))
    out = str(tmp_path / "out")
    code = {
        "eval": lambda: evaluate.main(["--policy", policy, "--episodes", "1", "--no-progress"]),
        "ppo --init": lambda: train.main(
            ["ppo", "--init", policy, "--steps", "8192", "--out", out, "--no-progress"]
        ),
        "collect dagger": lambda: collect.main(
            ["dagger", "--policy", policy, "--out", out, "--iterations", "1", "--episodes", "1"]
        ),
    }[entry]()
    assert code == 2
    one_error(capsys, repr(task))


@pytest.mark.parametrize("features", [[], ["observation.state"], {"observation.state": 13}])
def test_eval_refuses_input_features_that_are_not_features(
    act_checkpoint, tmp_path, capsys, features
):
    """#52: a LeRobot config whose input_features is a list ended in an AttributeError."""
    folder = hostile(
        act_checkpoint, tmp_path, "config.json", lambda d: d.update(input_features=features)
    )
    argv = ["--policy", str(folder), "--task", "altitude", "--aircraft", "c172p"]
    assert evaluate.main([*argv, "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, "input_features")
