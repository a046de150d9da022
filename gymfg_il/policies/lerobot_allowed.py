"""What a LeRobot checkpoint may name, checked before LeRobot reads it.

LeRobot builds a checkpoint from names its files give: ``config.json``'s ``type`` picks the
policy class, and each step of ``policy_preprocessor.json`` / ``policy_postprocessor.json``
is a ``registry_name`` (looked up in LeRobot's registry) or a ``class`` (a dotted path that
LeRobot imports and calls with the step's ``config``). A ``class`` of
``subprocess.Popen`` runs a command while the checkpoint loads, before any check of
LeRobot's refuses it. So GymFG reads those files itself first and lets through only the
names LeRobot's own policies write (LeRobot 0.6), collected here:

- policy types that build from their files alone (no ``trust_remote_code``): ACT,
  diffusion, TD-MPC, VQ-BeT, multi-task DiT, pi0, pi0.5 and SmolVLA;
- their processor steps, all of which LeRobot saves by ``registry_name`` (a ``class`` entry
  is never LeRobot's own and is refused);
- state files by plain name inside the checkpoint folder, and a torchvision ResNet as the
  vision backbone (the modeling code calls ``torchvision.models.<vision_backbone>``).

Left out on purpose: steps that load code or tokenizers with ``trust_remote_code``
(``action_tokenizer_processor``; pi0-FAST, GR00T, Wall-X) and robot/teleoperation steps no
policy checkpoint holds.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError

POLICY_TYPES = frozenset(
    {"act", "diffusion", "tdmpc", "vqbet", "multi_task_dit", "pi0", "pi05", "smolvla"}
)
# every registry_name the processors of POLICY_TYPES write (lerobot/processor/factory.py's
# default steps, and policies/{pi0,pi05,smolvla}/processor_*.py)
PROCESSOR_STEPS = frozenset(
    {
        "rename_observations_processor",
        "to_batch_processor",
        "device_processor",
        "normalizer_processor",
        "unnormalizer_processor",
        "tokenizer_processor",
        "relative_actions_processor",
        "absolute_actions_processor",
        "pi0_new_line_processor",
        "pi05_prepare_state_tokenizer_processor_step",
        "smolvla_new_line_processor",
    }
)
PROCESSOR_FILES = ("policy_preprocessor.json", "policy_postprocessor.json")
BACKBONES = frozenset({"resnet18", "resnet34", "resnet50", "resnet101", "resnet152"})
FIX = "use a checkpoint lerobot-train wrote for one of LeRobot's own policies, or train it again"


class UnsafeCheckpointError(ConfigError):
    """A LeRobot checkpoint that names a class, step or module LeRobot's own policies never
    do; refused before LeRobot imports or calls anything it names."""


def check_checkpoint(folder: Path) -> None:
    """Refuse (``UnsafeCheckpointError``, naming each offending entry) a checkpoint at
    ``folder`` whose files name anything outside the allow-lists above."""
    folder = Path(folder)
    problems = _config_problems(folder / "config.json")
    for name in PROCESSOR_FILES:
        problems += _pipeline_problems(folder, name)
    if problems:
        head = f"the LeRobot checkpoint at {folder} names what GymFG does not load ({FIX})"
        raise UnsafeCheckpointError(
            head + ":\n" + "\n".join(f"  - {p}" for p in problems)
            if len(problems) > 1
            else f"{head}: {problems[0]}"
        )


def _read(path: Path) -> Any:
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError, ValueError) as err:
        raise UnsafeCheckpointError(f"{path} cannot be read as JSON ({err}); {FIX}") from None


def _config_problems(path: Path) -> list[str]:
    config = _read(path)
    if not isinstance(config, dict):
        return [f"{path.name} is not a JSON object"]
    problems = []
    kind = config.get("type")
    if not (isinstance(kind, str) and kind in POLICY_TYPES):
        problems.append(
            f"config.json: policy type {kind!r} is not one of {', '.join(sorted(POLICY_TYPES))}"
        )
    backbone = config.get("vision_backbone", "resnet18")
    if not (isinstance(backbone, str) and backbone in BACKBONES):
        problems.append(
            f"config.json: vision_backbone {backbone!r} is not a ResNet torchvision ships "
            f"({', '.join(sorted(BACKBONES))})"
        )
    return problems


def _pipeline_problems(folder: Path, name: str) -> list[str]:
    pipeline = _read(folder / name)
    if pipeline is None:
        return []  # LeRobot says which file is missing; nothing in it is run
    steps = pipeline.get("steps") if isinstance(pipeline, dict) else None
    if not isinstance(steps, list):
        return [f"{name} holds no list of steps"]
    problems = []
    for i, step in enumerate(steps):
        where = f"{name} step {i}"
        if not isinstance(step, dict):
            problems.append(f"{where} is {type(step).__name__}, not a step")
            continue
        if "class" in step:
            problems.append(
                f"{where} names class {step['class']!r}: LeRobot would import and call it; "
                "LeRobot's own steps are named by registry_name"
            )
        registry = step.get("registry_name")
        if "registry_name" in step and not (
            isinstance(registry, str) and registry in PROCESSOR_STEPS
        ):
            problems.append(
                f"{where} names registry_name {registry!r}, not a step of LeRobot's own "
                f"policies ({', '.join(sorted(PROCESSOR_STEPS))})"
            )
        elif "class" not in step and "registry_name" not in step:
            problems.append(f"{where} names no registry_name")
        state = step.get("state_file")
        if state is not None and not _plain_file(state):
            problems.append(f"{where} state_file {state!r} is not a file name in the folder")
    return problems


def _plain_file(name: object) -> bool:
    return (
        isinstance(name, str)
        and name.endswith(".safetensors")
        and Path(name).name == name
        and name not in ("", ".", "..")
        and "\\" not in name
    )
