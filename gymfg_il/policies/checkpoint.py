"""A trained policy on disk: ``config.json`` (its type, its settings, the dataset's statistics
and what the training run records) beside ``model.safetensors`` (its weights)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.files import JSON_LIMIT, WEIGHTS_LIMIT, check_regular, read_regular
from gymfg_il.policies.factory import make_policy, policy_type

CONFIG_FILE, WEIGHTS_FILE = "config.json", "model.safetensors"
REPLACE = "put the file `train bc` wrote in its place, or train the policy again"


def _stats_json(stats: dict[str, np.ndarray]) -> dict[str, list[float]]:
    return {k: np.asarray(stats[k], dtype=np.float64).tolist() for k in ("mean", "std")}


def save_policy(
    policy: Any,
    out: Path,
    meta: dict[str, Any],
    obs_stats: dict[str, np.ndarray],
    action_stats: dict[str, np.ndarray],
) -> Path:
    """Write ``out/config.json`` and ``out/model.safetensors``."""
    from safetensors.torch import save_file

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    settings = policy.config.to_dict()
    config = {
        "type": settings["type"],
        "policy": settings,
        "obs_stats": _stats_json(obs_stats),
        "action_stats": _stats_json(action_stats),
        **meta,
    }
    (out / CONFIG_FILE).write_text(json.dumps(config, indent=2))
    state = {k: v.detach().cpu().contiguous() for k, v in policy.state_dict().items()}
    save_file(state, str(out / WEIGHTS_FILE))
    return out


def read_config(path: Path) -> dict[str, Any]:
    """What the policy checkpoint at ``path`` says of itself (its ``config.json``), after
    checking that it and its weights are regular files (``gymfg_il.files``)."""
    path = Path(path)
    try:
        check_regular(path / WEIGHTS_FILE, WEIGHTS_LIMIT, REPLACE)
        text = read_regular(path / CONFIG_FILE, JSON_LIMIT, REPLACE)
    except FileNotFoundError:
        raise ConfigError(
            f"{path} is not a policy checkpoint (needs {CONFIG_FILE} and {WEIGHTS_FILE}): give "
            "a folder `python -m gymfg_il.train bc` wrote, or a LeRobot checkpoint "
            "(lerobot-train's output folder or its .../pretrained_model)"
        ) from None
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path / CONFIG_FILE} is not valid JSON ({err}); train again") from None
    need = ("type", "policy", "obs_stats", "action_stats")
    missing = [k for k in need if not isinstance(data, dict) or k not in data]
    if missing and isinstance(data, dict) and "input_features" in data:
        raise ConfigError(_lerobot_here(path, data.get("type")))
    if missing:
        raise ConfigError(
            f"{path / CONFIG_FILE} is neither our policy config (no {missing}) nor a LeRobot "
            "policy's (no input_features): give a folder `train bc` or lerobot-train wrote"
        )
    return data


def _lerobot_here(path: Path, kind: Any) -> str:
    """Why a LeRobot checkpoint cannot be what needs one of GymFG's own policies (the start
    of ``train ppo --init``; ``eval`` flies LeRobot checkpoints through their own loader)."""
    from gymfg_il.policies.configuration_mlp import MLPConfig
    from gymfg_il.policies.factory import policy_types

    types = policy_types()
    mlps = [n for n, t in types.items() if issubclass(t.config, MLPConfig)]
    return (
        f"{path} is a LeRobot checkpoint ({kind!r}), not one of GymFG's own policies "
        f"({', '.join(types)}): PPO fine-tunes GymFG's own MLP policies ({', '.join(mlps)}; "
        "`train bc --policy mlp` writes one) and cannot start from a LeRobot checkpoint; "
        "eval flies it as it is"
    )


def load_policy(path: Path, device: str = "cpu") -> tuple[Any, dict[str, Any]]:
    """(policy module in eval mode on ``device``, its config dict)."""
    from safetensors.torch import load_file

    meta = read_config(path)
    try:
        settings = dict(meta["policy"])
        config = policy_type(settings.get("type", meta["type"])).config.from_dict(settings)
        obs = {k: np.array(v) for k, v in meta["obs_stats"].items()}
        act = {k: np.array(v) for k, v in meta["action_stats"].items()}
        policy = make_policy(config, obs, act)
        policy.load_state_dict(load_file(str(Path(path) / WEIGHTS_FILE)))
    except ConfigError:
        raise
    except Exception as err:  # safetensors, torch and the config raise many types
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ConfigError(
            f"the policy at {path} cannot be loaded ({first}); its {WEIGHTS_FILE} is damaged or "
            f"does not match its {CONFIG_FILE}: train it again"
        ) from None
    return policy.to(device).eval(), meta
