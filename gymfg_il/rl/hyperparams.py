"""PPO's own settings per task (``PPOSettings``), read from ``hyperparams.toml`` beside this
module as rl-baselines3-zoo keeps them: a ``[default]`` table, and a table per task whose
values replace the default's for that task (``table``). ``PPORunConfig`` resolves them, the
flags given to ``train ppo`` replacing both."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.typecheck import type_problems

HYPERPARAMS = Path(__file__).with_name("hyperparams.toml")


@dataclass(frozen=True)
class PPOSettings:
    """PPO's settings for one run, resolved (what each does: ``PPORunConfig``'s fields of the
    same names). None: the rule ``PPORunConfig`` states (``actor_rate``, ``discounts``,
    ``warmup_steps``, ``anchor_span``)."""

    rollout_steps: int
    batch_size: int
    epochs: int
    lr: float
    clip_range: float
    target_kl: float
    action_std: float
    success_bonus: float
    anchor: float
    critic: list[int] = field(default_factory=lambda: [256, 256])
    actor_lr: float | None = None
    gamma: float | None = None
    gae_lambda: float | None = None
    critic_warmup: int | None = None
    anchor_steps: int | None = None

    def problems(self) -> list[str]:
        """What is out of range, each naming the setting and its range."""
        counts = ("rollout_steps", "epochs")
        problems = [f"{n}={getattr(self, n)} must be >= 1" for n in counts if getattr(self, n) < 1]
        if self.batch_size < 2:
            problems.append(
                f"batch_size={self.batch_size} must be >= 2 (PPO normalises each batch's "
                "advantages)"
            )
        for name in ("lr", "actor_lr"):
            value = getattr(self, name)
            if value is not None and not 0 < value < 1:
                problems.append(f"{name}={value} must lie in (0, 1)")
        for name in ("gamma", "gae_lambda"):
            value = getattr(self, name)
            if value is not None and not 0 < value <= 1:
                problems.append(f"{name}={value} must lie in (0, 1]")
        if not 0 < self.clip_range < 1:
            problems.append(f"clip_range={self.clip_range} must lie in (0, 1)")
        for name in ("target_kl", "anchor", "success_bonus"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                problems.append(f"{name}={value} must be a number >= 0")
        if not 0 < self.action_std <= 10:
            problems.append(f"action_std={self.action_std} must lie in (0, 10]")
        for name in ("critic_warmup", "anchor_steps"):
            value = getattr(self, name)
            if value is not None and value < 0:
                problems.append(f"{name}={value} must be >= 0 env steps")
        if not self.critic or min(self.critic) < 1:
            problems.append(f"critic={self.critic}: want a non-empty list of widths > 0")
        return problems


NAMES = tuple(f.name for f in dataclasses.fields(PPOSettings))


def table(task: str | None, path: Path | None = None) -> dict[str, Any]:
    """The settings ``path`` (default: ``HYPERPARAMS``) gives ``task``: its ``[default]``
    table, with the task's own table's values in place of the default's (no task, or none of
    its own: the default's)."""
    path = path or HYPERPARAMS
    try:
        data = tomllib.loads(Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as err:
        raise ConfigError(f"cannot read PPO's settings from {path}: {err}") from None
    problems = []
    for name, entries in data.items():
        if not isinstance(entries, dict):
            problems.append(f"{name}: not a table ([default] or [TASK])")
            continue
        problems += [
            f"[{name}] {key}: no setting of PPO's (the settings: {', '.join(NAMES)})"
            for key in entries
            if key not in NAMES
        ]
    if "default" not in data:
        problems.append("no [default] table")
    if problems:
        raise ConfigError(f"{path}: " + "; ".join(problems))
    own = data.get(task, {}) if task else {}
    return {**data["default"], **own}


def resolve(task: str | None, given: dict[str, Any]) -> PPOSettings:
    """PPO's settings for a run of ``task``: ``given`` (the flags), else the task's in
    ``HYPERPARAMS``; a value of the wrong type (from the file) is an error naming it."""
    values = {**table(task), **given}
    required = [f.name for f in dataclasses.fields(PPOSettings) if f.default is dataclasses.MISSING]
    missing = [name for name in required if name not in values]
    if missing:
        raise ConfigError(f"{HYPERPARAMS}: [default] lacks {', '.join(missing)}")
    settings = PPOSettings(**values)
    typed = type_problems(settings)
    if typed:
        raise ConfigError(f"PPO's settings (given, or in {HYPERPARAMS}): " + "; ".join(typed))
    return settings
