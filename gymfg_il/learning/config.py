"""The settings of a behaviour-cloning run (``TrainConfig``) and the defaults that depend on
the data: how many epochs, which device."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.policies.configuration import PolicyConfig
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.tasks.grades import GRADES
from gymfg_il.typecheck import type_problems

DEFAULT_DATASET = Path("datasets/sample-altitude-c172p/dataset")
EPOCHS_AUTOPILOT, EPOCHS_PERSON = 60, 20  # the default epochs (TrainConfig.epochs)


def validation_words(loss: float, held_frames: int | None = None) -> str:
    """The validation loss in words for a report line: ``validation loss 0.0123``, or why
    there is none (``held_frames``: the frames held out, where the caller knows them)."""
    if not math.isnan(loss):
        return f"validation loss {loss:.4f}"
    if held_frames:
        return "no validation loss (the held-out episodes are shorter than the policy's window)"
    return "no validation loss (no episode held out: --val-fraction of them is under one)"


@dataclass
class TrainConfig:
    """Behaviour-cloning run.

    Attributes:
        dataset: LeRobot dataset folder (default: the bundled sample).
        out: where the checkpoint goes, replacing any policy there (default:
            policies/bc-<task>-<aircraft>-<policy>, or -2, -3, ... where that holds one).
        policy: the policy trained: a registered policy configuration
            (``policies.factory``) with its settings; on the command line ``--policy`` names
            its type and each setting is a flag of its own.
        epochs: passes over the training samples (default: 60 for an autopilot's
            demonstrations, 20 where a person or the synthetic pilot flew any of them;
            a policy type may cap it, vision at 20).
        batch_size: samples (frames, or a policy's windows of frames) per gradient step.
        lr: AdamW learning rate (cosine-decayed to 5 % over the run).
        weight_decay: AdamW weight decay.
        seed: seeds the split, the initialisation and the shuffling.
        val_fraction: share of the episodes held out for a validation loss (whole
            episodes, rounded down: none where the share is under one episode, so that
            five demonstrations all train; 0.2 holds one of five out).
        device: cpu, cuda, or auto (cuda when present).
        obs_noise: std of Gaussian noise added to the normalised observations while training
            (0 = none).
        mixed_tasks: train one policy on episodes of different tasks that observe the same
            variables (altitude with altitude-dynamic, say). Without it a dataset of several
            tasks is refused, naming each task's episodes; tasks that observe different
            variables are refused either way.
        select: train only on the episodes that meet every one of these: ``success`` or
            ``failure`` (the task's verdict, stored as each episode was collected),
            ``mark=success`` or ``mark=failure`` (the pilot's own mark),
            ``grade=GRADE`` (the task's grade, ``tasks.grades``: that grade or a better
            one; excellent, good, fair, unsatisfactory), ``pilot=NAME``
            (``collect manual --pilot-name``), ``source=NAME`` (``human``,
            ``synthetic``, ``autopilot``, ...). Example: ``--select success pilot=ann``.
        weight: ``grade``: draw each episode's samples in proportion to its grade's weight
            (``GRADE_WEIGHTS``: excellent 4, good 3, fair 2, unsatisfactory 1), so better
            demonstrations teach more and worse ones still count; "" (default): every
            sample alike.
        shift: pair each observation with the action taken this many steps later (the
            pilot's reaction time answered for: the policy acts at once where the pilot acted
            late), or ``auto``: each pilot's own reaction time, estimated from their
            demonstrations (``learning.reaction``), on the episodes a person or the synthetic
            pilot flew. Default 0.
        before_first_input: also train on the frames of a person's (or the synthetic
            pilot's) episodes before their first input; by default those are left out, as
            hands at rest whatever the state (``Frames.from_first_input``).
        threads: CPU threads torch uses on cpu (0 = torch's own choice; default: the policy
            type's, 1, or 0 for vision, whose convolutions gain from more).
    """

    dataset: Path = DEFAULT_DATASET
    out: Path | None = None
    policy: PolicyConfig = field(default_factory=MLPConfig, metadata={"cli": False})
    epochs: int | None = None
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 1e-4
    seed: int = 0
    val_fraction: float = 0.1
    device: str = "cpu"
    obs_noise: float = 0.0
    mixed_tasks: bool = False
    select: list[str] = field(default_factory=list)
    weight: str = ""
    shift: str = "0"
    before_first_input: bool = False
    threads: int | None = None

    def __post_init__(self) -> None:
        if isinstance(self.policy, str):
            raise ConfigError(
                f"policy={self.policy!r}: give a policy configuration, "
                f"policies.factory.make_config({self.policy!r}, **settings)"
            )
        typed = type_problems(self)
        if typed:
            raise ConfigError(join_problems("train config", typed))
        self.dataset = Path(self.dataset)
        problems = []
        if self.threads is not None and self.threads < 0:
            problems.append(f"threads={self.threads}: want 0 (torch decides) or more")
        if (self.epochs is not None and self.epochs < 1) or self.batch_size < 1:
            problems.append("epochs and batch_size must be >= 1")
        if not 0 < self.lr <= 1:  # AdamW moves each weight by about lr a step
            problems.append(f"lr={self.lr} must lie in (0, 1] (default 1e-3)")
        if not (self.weight_decay >= 0 and self.lr * self.weight_decay < 1):
            problems.append(
                f"weight_decay={self.weight_decay} must be >= 0 with lr x weight_decay < 1 "
                "(each step shrinks the weights by that share)"
            )
        if not (self.obs_noise >= 0 and math.isfinite(self.obs_noise)):
            problems.append(f"obs_noise={self.obs_noise} must be a number >= 0")
        if not 0.0 <= self.val_fraction < 1.0:
            problems.append(f"val_fraction={self.val_fraction} must lie in [0, 1)")
        if self.device not in ("cpu", "cuda", "auto") and not self.device.startswith("cuda:"):
            problems.append(f"device={self.device!r}: use cpu, cuda, cuda:N or auto")
        problems += [selection_problem(term) for term in self.select if selection_problem(term)]
        if self.shift != "auto" and not (
            re.fullmatch("[0-9]{1,3}", self.shift) and int(self.shift) <= 120
        ):
            problems.append(f"shift={self.shift!r}: want a number of steps (0-120) or auto")
        if self.weight not in ("", "grade"):
            problems.append(f"weight={self.weight!r}: want grade, or leave it out")
        if problems:
            raise ConfigError(join_problems("train config", problems))

    @property
    def threads_wanted(self) -> int:
        """The CPU threads to train with: ``threads``, else the policy type's default."""
        return self.threads if self.threads is not None else self.policy.default_threads


SELECT_KEYS = {"mark": ("success", "failure"), "grade": GRADES, "pilot": None, "source": None}
GRADE_WEIGHTS = dict(zip(GRADES, (4.0, 3.0, 2.0, 1.0), strict=True))  # ``TrainConfig.weight``


def selection_problem(term: str) -> str:
    """What is wrong with one ``select`` term, or ""."""
    if term in ("success", "failure"):
        return ""
    key, eq, value = term.partition("=")
    if eq and key in SELECT_KEYS and value:
        allowed = SELECT_KEYS[key]
        if allowed is None or value in allowed:
            return ""
        return f"select {term!r}: {key}= takes {' or '.join(allowed)}"
    return (
        f"select {term!r}: want success, failure, mark=success, mark=failure, grade=GRADE, "
        "pilot=NAME or source=NAME"
    )


def default_epochs(frames: Any) -> int:
    """``EPOCHS_PERSON`` when a person or the synthetic pilot flew any demonstrated episode
    (source ``human``, ``synthetic``, or a takeover ``<policy>+human``), else
    ``EPOCHS_AUTOPILOT``."""
    sources = frames.episodes.get("gymfg/source") or []
    person = any(str(s).split("+")[-1] in ("human", "synthetic") for s in sources)
    return EPOCHS_PERSON if person else EPOCHS_AUTOPILOT


def epochs_for(cfg: TrainConfig, frames: Any) -> int:
    """The epochs ``cfg`` trains for: its own, else the default for its data, capped by its
    policy type's ``max_default_epochs``."""
    if cfg.epochs:
        return cfg.epochs
    cap = cfg.policy.max_default_epochs
    return default_epochs(frames) if cap is None else min(cap, default_epochs(frames))


def resolve_device(device: str) -> str:
    import torch

    if device == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise ConfigError(f"device={device!r} but no CUDA device is available; use cpu")
    return device
