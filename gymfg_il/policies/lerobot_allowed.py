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
  vision backbone (the modeling code calls ``torchvision.models.<vision_backbone>``);
- the models and tokenizers LeRobot fetches by name (from the Hub, or a local folder) only
  as its own policies name them: a ``tokenizer_processor`` step's ``tokenizer_name`` and
  ``config.json``'s ``vlm_model_name`` (SmolVLA), ``vision_encoder_name`` and
  ``text_encoder_name`` (multi-task DiT), pinned to the names those policies write.

Left out on purpose: steps that load code or tokenizers with ``trust_remote_code``
(``action_tokenizer_processor``; pi0-FAST, GR00T, Wall-X) and robot/teleoperation steps no
policy checkpoint holds. LeRobot is given the bytes that were checked (``checked_files``,
copied into a private folder), never the checkpoint's folder again, which could have changed
in between; the weights it reads from the folder are safetensors, which hold no code.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.files import JSON_LIMIT, WEIGHTS_LIMIT, read_regular

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
# what LeRobot fetches by name: the tokenizers its policies' processors name (pi0 and pi0.5:
# PaliGemma's; SmolVLA: its VLM's; multi-task DiT: its CLIP text encoder's) and, in
# config.json, the models SmolVLA and multi-task DiT load (their configurations' defaults)
PINNED_MODELS = {
    "vlm_model_name": "HuggingFaceTB/SmolVLM2-500M-Video-Instruct",
    "vision_encoder_name": "openai/clip-vit-base-patch16",
    "text_encoder_name": "openai/clip-vit-base-patch16",
}
TOKENIZERS = frozenset({"google/paligemma-3b-pt-224", *PINNED_MODELS.values()})
FIX = "use a checkpoint lerobot-train wrote for one of LeRobot's own policies, or train it again"
REPLACE = "put the file lerobot-train wrote in its place, or train the checkpoint again"


class UnsafeCheckpointError(ConfigError):
    """A LeRobot checkpoint that names a class, step or module LeRobot's own policies never
    do; refused before LeRobot imports or calls anything it names."""


def checked_files(folder: Path) -> dict[str, bytes]:
    """The files of the checkpoint at ``folder`` that name things (``config.json`` and the
    processor pipelines), with the state files the pipelines name, as read once and checked;
    LeRobot is to load these bytes, not the folder, which may have changed since. Refuses
    (``UnsafeCheckpointError``, naming each offending entry) anything outside the lists."""
    folder = Path(folder)
    files = {n: d for n in ("config.json", *PROCESSOR_FILES) if (d := _bytes(folder / n))}
    problems = _config_problems(_parsed(folder, "config.json", files))
    states: list[str] = []
    for name in PROCESSOR_FILES:
        if name in files:
            problems += _pipeline_problems(name, _parsed(folder, name, files), states)
    if problems:
        head = f"the LeRobot checkpoint at {folder} names what GymFG does not load ({FIX})"
        raise UnsafeCheckpointError(
            head + ":\n" + "\n".join(f"  - {p}" for p in problems)
            if len(problems) > 1
            else f"{head}: {problems[0]}"
        )
    for state in states:
        if data := _bytes(folder / state):
            files[state] = data  # one missing is LeRobot's to name
    return files


def _bytes(path: Path) -> bytes | None:
    """The file's bytes, None where it is missing; a regular file only, else
    ``NotRegularFileError`` (a FIFO hung the load, /dev/zero filled memory)."""
    limit = JSON_LIMIT if path.suffix == ".json" else WEIGHTS_LIMIT
    try:
        return read_regular(path, limit, REPLACE)
    except FileNotFoundError:
        return None


def _parsed(folder: Path, name: str, files: dict[str, bytes]) -> Any:
    try:
        return json.loads(files.get(name, b"null"))
    except (UnicodeDecodeError, ValueError) as err:
        raise UnsafeCheckpointError(f"{folder / name} is not valid JSON ({err}); {FIX}") from None


def _config_problems(config: Any) -> list[str]:
    if not isinstance(config, dict):
        return ["config.json is not a JSON object"]
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
    for key, pinned in PINNED_MODELS.items():
        if key in config and config[key] != pinned:
            problems.append(
                f"config.json: {key} {config[key]!r} is not the model LeRobot's own policy "
                f"names ({pinned!r}); LeRobot would fetch and load it"
            )
    return problems


def _pipeline_problems(name: str, pipeline: Any, states: list[str]) -> list[str]:
    """What in the pipeline ``name`` is not on the lists; adds its state files to
    ``states``."""
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
        elif registry == "tokenizer_processor":
            problems += _tokenizer_problems(where, step.get("config"))
        state = step.get("state_file")
        if state is not None and not _plain_file(state):
            problems.append(f"{where} state_file {state!r} is not a file name in the folder")
        elif state is not None:
            states.append(state)
    return problems


def _tokenizer_problems(where: str, config: Any) -> list[str]:
    """A tokenizer step names a tokenizer LeRobot fetches and loads (``AutoTokenizer``):
    only the ones LeRobot's own policies name (``TOKENIZERS``)."""
    name = config.get("tokenizer_name") if isinstance(config, dict) else None
    if isinstance(name, str) and name in TOKENIZERS:
        return []
    return [
        f"{where} names tokenizer_name {name!r}, not a tokenizer of LeRobot's own policies "
        f"({', '.join(sorted(TOKENIZERS))}); LeRobot would fetch and load it"
    ]


def _plain_file(name: object) -> bool:
    return (
        isinstance(name, str)
        and name.endswith(".safetensors")
        and Path(name).name == name
        and name not in ("", ".", "..")
        and "\\" not in name
    )
