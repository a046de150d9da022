"""A LeRobot checkpoint (ACT, diffusion, ... trained with ``lerobot-train`` on our datasets)
flown as an Agent, beside our own policies.

A LeRobot checkpoint is a ``pretrained_model`` folder: ``config.json`` (with ``type`` and
``input_features``), ``model.safetensors``, the processor pipelines and ``train_config.json``.
``find_pretrained`` accepts that folder, the checkpoint folder above it, or the run's output
folder (its ``checkpoints/last``). The agent feeds the policy what our datasets gave it in
training: ``observation.state`` (the task's observation), ``observation.environment_state``
(its task columns) and ``observation.images.<view>`` (the env's camera), through the
checkpoint's own pre- and post-processors (normalisation included).
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.files import JSON_LIMIT, WEIGHTS_LIMIT, check_regular, read_regular
from gymfg_il.policies.lerobot_allowed import REPLACE, checked_files
from gymfg_il.sim.properties import task_columns

EITHER = "put the file `train bc` or lerobot-train wrote in its place, or train the policy again"
STATE, ENVIRONMENT, IMAGES = (
    "observation.state",
    "observation.environment_state",
    "observation.images.",
)


def _lerobot_config(folder: Path) -> dict[str, Any] | None:
    """The LeRobot config of the checkpoint in ``folder``, or None where there is none (no
    config.json, or ours); NotRegularFileError where config.json or the weights are not
    regular files (``gymfg_il.files``)."""
    data = _json(folder / "config.json", EITHER)  # ours or LeRobot's: not known yet
    if not isinstance(data, dict) or "input_features" not in data or "obs_stats" in data:
        return None
    try:
        check_regular(folder / "model.safetensors", WEIGHTS_LIMIT, REPLACE)
    except FileNotFoundError:
        return None
    return data if "type" in data else None


def _json(path: Path, fix: str = REPLACE) -> Any:
    """The JSON in the regular file at ``path``; None where it is missing or not JSON."""
    try:
        raw = read_regular(path, JSON_LIMIT, fix)
    except FileNotFoundError:
        return None
    try:
        return json.loads(raw)
    except ValueError:  # UnicodeDecodeError is one
        return None


def find_pretrained(path: Path) -> Path | None:
    """The LeRobot ``pretrained_model`` folder at or under ``path``, or None."""
    path = Path(path)
    for folder in (path, path / "pretrained_model", path / "checkpoints/last/pretrained_model"):
        if _lerobot_config(folder) is not None:
            return folder
    return None


def lerobot_meta(folder: Path) -> dict[str, Any]:
    """What the checkpoint says of itself, in the keys our checkpoints' config uses: its
    type, input features, and the dataset it was trained on (``dataset``, when recorded)."""
    config = _lerobot_config(folder)
    assert config is not None
    train = _json(folder / "train_config.json")  # lerobot-train's, with the dataset's root
    dataset = train.get("dataset") if isinstance(train, dict) else None
    root = dataset.get("root") if isinstance(dataset, dict) else None
    given = config["input_features"]
    if not (isinstance(given, dict) and all(isinstance(v, dict) for v in given.values())):
        raise ConfigError(
            f"{folder / 'config.json'}: input_features is a {type(given).__name__}, not an "
            "object of features as lerobot-train writes it ({name: {type, shape}}); the "
            "checkpoint is damaged or not LeRobot's: train it again"
        )
    features = {str(k): v.get("shape") for k, v in given.items()}
    cameras = sorted(k.removeprefix(IMAGES) for k in features if k.startswith(IMAGES))
    return {
        "type": f"lerobot:{config['type']}",
        "name": f"lerobot-{config['type']}",
        "lerobot": True,
        "input_features": features,
        "cameras": cameras,
        "dataset": root if isinstance(root, str) else None,
    }


class LeRobotAgent:
    """Fly the LeRobot checkpoint in ``folder``; ``see[view]()`` gives the camera's frame of
    the current state (``AgentSpec.make`` wires the env's camera)."""

    def __init__(self, folder: Path, device: str = "cpu") -> None:
        checked = checked_files(folder)  # before LeRobot imports or calls anything they name
        import torch
        from lerobot.configs.policies import PreTrainedConfig
        from lerobot.policies.factory import get_policy_class, make_pre_post_processors

        self.meta = lerobot_meta(folder)
        try:
            with tempfile.TemporaryDirectory(prefix="gymfg-lerobot-") as private:
                for name, data in checked.items():  # LeRobot reads what was checked
                    (Path(private) / name).write_bytes(data)
                cfg = PreTrainedConfig.from_pretrained(private)
                cfg.device = device
                policy = get_policy_class(cfg.type).from_pretrained(str(folder), config=cfg)
                self.pre, self.post = make_pre_post_processors(
                    policy_cfg=cfg,
                    pretrained_path=private,
                    preprocessor_overrides={"device_processor": {"device": device}},
                )
            self.policy = policy
        except Exception as err:  # lerobot, draccus, torch and safetensors raise many types
            first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
            raise ConfigError(
                f"the LeRobot checkpoint at {folder} cannot be loaded ({first}); train it again "
                "with lerobot-train, or give its pretrained_model folder"
            ) from None
        self.policy.eval()
        self._torch = torch
        self._columns: list[int] = []
        self.see: dict[str, Callable[[], np.ndarray]] = {}
        # LeRobot's policies queue observations and actions across steps (``reset`` empties
        # the queues): called at every step, also where a person flies (``Agent``)
        self.stateful = True

    @property
    def name(self) -> str:
        return str(self.meta["name"])

    @property
    def camera_sizes(self) -> dict[str, int]:
        """The square size each camera view is given at, from the input features."""
        features = self.meta["input_features"]
        return {v: int(features[IMAGES + v][-1]) for v in self.meta["cameras"]}

    def check_observation(self, names: Sequence[str]) -> None:
        """The task's observation fits the policy's input features (else a clear error)."""
        features = self.meta["input_features"]
        columns = task_columns(names)
        problems = []
        state = features.get(STATE)
        if state is None or int(state[0]) != len(names):
            problems.append(f"{STATE} {state} against the task's {len(names)} observations")
        env_state = features.get(ENVIRONMENT)
        if env_state is not None and int(env_state[0]) != len(columns):
            problems.append(f"{ENVIRONMENT} {env_state} against its {len(columns)} task columns")
        other = sorted(
            k for k in features if k not in (STATE, ENVIRONMENT) and not k.startswith(IMAGES)
        )
        if other:
            problems.append(f"inputs GymFG does not give: {other}")
        if problems:
            raise ConfigError(
                f"{self.name} does not fit this flight ({'; '.join(problems)}): fly it on the "
                "task and aircraft of the dataset it was trained on (--task, --aircraft)"
            )
        self._columns = columns if env_state is not None else []

    def reset(self, seed: int | None = None) -> None:
        self.policy.reset()  # the action queue of chunking policies

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        torch = self._torch
        obs = torch.as_tensor(np.asarray(observation, dtype=np.float32))
        batch: dict[str, Any] = {STATE: obs.unsqueeze(0)}
        if self._columns:
            batch[ENVIRONMENT] = obs[self._columns].unsqueeze(0)
        for view in self.meta["cameras"]:
            if view not in self.see:
                raise ConfigError(
                    f"{self.name} flies by its camera ({view}): fly it in a GymFG env (eval), "
                    "which gives it the camera's frames"
                )
            frame = torch.as_tensor(self.see[view]()).permute(2, 0, 1).float() / 255.0
            batch[IMAGES + view] = frame.unsqueeze(0)
        batch["task"] = [""]
        with torch.inference_mode():
            action = self.post(self.policy.select_action(self.pre(batch)))
        out: np.ndarray = action[0].double().cpu().numpy()
        return out
