"""Hostile and broken inputs to loading checkpoints and to `train bc` (red team, issue 32):
a checkpoint never makes GymFG import or call what its files name, training never saves a
policy from non-finite data, a killed save leaves the whole old policy or the whole new
one, and a damaged dataset is one line "error: ..." with exit status 2."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from gymfg_il import eval as evaluate
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
    ],
)
def test_names_outside_lerobots_own_policies_are_refused(
    act_checkpoint, tmp_path, file, change, needle
):
    folder = hostile(act_checkpoint, tmp_path, file, change)
    with pytest.raises(UnsafeCheckpointError) as err:
        LeRobotAgent(folder)
    assert needle in str(err.value)
