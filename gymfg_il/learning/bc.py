"""Behaviour cloning: regress the demonstrator's action from the observation."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.typecheck import type_problems

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec

DEFAULT_DATASET = Path("datasets/sample-altitude-c172p/dataset")
EPOCHS_AUTOPILOT, EPOCHS_PERSON = 60, 20  # the default epochs (TrainConfig.epochs)
EPOCHS_VISION = 20  # a vision policy's validation loss stops falling by then, at ~25 s each
# validation over training loss above which train says the policy memorised. Measured on roll
# (c172p, 20 demonstrations, trimmed starts): without noise 35x, and the policy crashed in 14 of
# 16 held-out episodes; with the default noise 10-20x (one held-out episode's elevator and
# throttle, which follow integrals the task does not observe) and 16 of 16 succeeded. Good
# default policies measured 1.6-20.1x, memorised ones 35-36x: a weak signal, kept for the case
# it was made for (demonstrations without noise).
OVERFIT_RATIO = 30.0
log = logging.getLogger(__name__)


@dataclass
class TrainConfig:
    """Behaviour-cloning run.

    Attributes:
        dataset: LeRobot dataset folder (default: the bundled sample).
        out: where the checkpoint goes (default: policies/bc-<task>-<aircraft>-<policy>).
        policy: policy type: mlp (default; one observation in, one action out), gru
            (recurrent), chunk (an observation history in, a chunk of future actions out,
            flown with temporal ensembling, as ACT does) or vision (a CNN over the camera's
            last ``frames`` frames plus the task's targets; needs a dataset collected with
            ``--images``).
        epochs: passes over the training frames (default: 60 for an autopilot's
            demonstrations, 20 where a person or the synthetic pilot flew any of them, 20 for
            a vision policy). At 30,
            an F-15 altitude policy cloned from 40 autopilot demonstrations held offsets of
            12-50 ft and succeeded in 10 of 12 held-out episodes; at 60, in all of them. A
            pilot's keyboard actions are noisy and 60 epochs memorise them: from 50 synthetic-
            pilot turns the policy succeeded in 11 of 16 held-out episodes (2 crashed) after 60
            epochs and in 16 of 16 after 20.
        batch_size: frames (or windows, for gru) per gradient step.
        lr: AdamW learning rate (cosine-decayed to 5 % over the run).
        weight_decay: AdamW weight decay.
        seed: seeds the split, the initialisation and the shuffling.
        val_fraction: share of episodes held out for validation loss (whole episodes).
        device: cpu, cuda, or auto (cuda when present).
        hidden: hidden widths (mlp) or the GRU width (gru, first value).
        sequence_length: gru only: training window in steps.
        history: chunk only: observations the policy sees (the current one and those before).
        chunk: chunk only: actions predicted at every step.
        camera: vision only: the dataset's camera the policy sees (front or chase).
        frames: vision only: camera frames the policy sees (the current one and those
            before; two show the rates).
        obs_noise: std of Gaussian noise added to the normalised observations while training
            (0 = none).
        mixed_tasks: train one policy on episodes of different tasks that observe the same
            variables (altitude with altitude-dynamic, say). Without it a dataset of several
            tasks is refused, naming each task's episodes; tasks that observe different
            variables are refused either way.
        threads: CPU threads torch uses on cpu (0 = torch's own choice; default: 1, or 0 for
            a vision policy). One is fastest for the small policies: the default MLP trained
            3x faster on 1 thread than on 2; the vision policy's convolutions 1.7x faster on 2.
    """

    dataset: Path = DEFAULT_DATASET
    out: Path | None = None
    policy: Literal["mlp", "gru", "chunk", "vision"] = "mlp"
    epochs: int | None = None
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 1e-4
    seed: int = 0
    val_fraction: float = 0.1
    device: str = "cpu"
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    sequence_length: int = 32
    history: int = 4
    chunk: int = 10
    camera: Literal["front", "chase"] = "front"
    frames: int = 2
    obs_noise: float = 0.0
    mixed_tasks: bool = False
    threads: int | None = None

    def __post_init__(self) -> None:
        typed = type_problems(self)
        if typed:
            raise ConfigError(join_problems("train config", typed))
        self.dataset = Path(self.dataset)
        problems = []
        if self.policy not in ("mlp", "gru", "chunk", "vision"):
            problems.append(f"policy={self.policy!r}: choose mlp, gru, chunk or vision")
        if self.history < 1 or self.chunk < 1 or self.frames < 1:
            problems.append(
                f"history={self.history}, chunk={self.chunk} and frames={self.frames} must be >= 1"
            )
        if self.frames > 16:  # each is a full camera frame per training sample in memory
            problems.append(f"frames={self.frames}: a vision policy sees 1 to 16 camera frames")
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
        if not self.hidden or min(self.hidden) < 1:
            problems.append(f"hidden={self.hidden} must be widths >= 1")
        if self.sequence_length < 2:
            problems.append(f"sequence_length={self.sequence_length} must be >= 2")
        if not 0.0 <= self.val_fraction < 1.0:
            problems.append(f"val_fraction={self.val_fraction} must lie in [0, 1)")
        if self.device not in ("cpu", "cuda", "auto") and not self.device.startswith("cuda:"):
            problems.append(f"device={self.device!r}: use cpu, cuda, cuda:N or auto")
        if problems:
            raise ConfigError(join_problems("train config", problems))


@dataclass
class TrainResult:
    out: Path
    train_loss: list[float]
    val_loss: list[float]
    seconds: float
    frames: int
    meta: dict[str, Any]

    @property
    def overfit(self) -> str:
        """A warning when the held-out episodes' loss is far above the training loss (the
        policy memorised its demonstrations), else ""."""
        train, val = self.train_loss[-1], self.val_loss[-1]
        if math.isnan(val) or val <= OVERFIT_RATIO * train or val < 1e-3:
            return ""
        return (
            f"validation loss {val:.4f} is {val / train:.1f}x the training loss {train:.4f}: "
            "the policy fits its demonstrations far better than episodes it has not seen, so "
            "it may not recover from its own deviations. More demonstrations help; so do "
            "DART noise for autopilot ones (collect autopilot --noise, 0.05 by default), "
            "`collect dagger`, and a person taking over from the policy (collect manual "
            "--assist)"
        )


def default_epochs(frames: Any) -> int:
    """``EPOCHS_PERSON`` when a person or the synthetic pilot flew any demonstrated episode
    (source ``human``, ``synthetic``, or a takeover ``<policy>+human``), else
    ``EPOCHS_AUTOPILOT``."""
    sources = frames.episodes.get("gymfg/source") or []
    person = any(str(s).split("+")[-1] in ("human", "synthetic") for s in sources)
    return EPOCHS_PERSON if person else EPOCHS_AUTOPILOT


def epochs_for(cfg: TrainConfig, frames: Any) -> int:
    """The epochs ``cfg`` trains for: its own, else the default for its policy and data."""
    if cfg.epochs:
        return cfg.epochs
    return (
        min(EPOCHS_VISION, default_epochs(frames))
        if cfg.policy == "vision"
        else default_epochs(frames)
    )


def resolve_device(device: str) -> str:
    import torch

    if device == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise ConfigError(f"device={device!r} but no CUDA device is available; use cpu")
    return device


def train_bc(
    cfg: TrainConfig,
    on_epoch: Callable[[int, float, float], None] | None = None,
    frames: Any = None,
) -> TrainResult:
    """Train, save the checkpoint and a loss-curve plot under ``cfg.out``."""
    import torch

    threads = torch.get_num_threads()
    wanted = cfg.threads if cfg.threads is not None else (0 if cfg.policy == "vision" else 1)
    if resolve_device(cfg.device) == "cpu" and wanted > 0:
        torch.set_num_threads(wanted)
    try:
        return _train(cfg, on_epoch, frames)
    finally:
        torch.set_num_threads(threads)  # the caller's setting, as it was


def _train(
    cfg: TrainConfig,
    on_epoch: Callable[[int, float, float], None] | None,
    frames: Any,
) -> TrainResult:
    import torch

    from gymfg_il.learning.data import TensorBatches, check_tasks, load_frames, split_by_episode
    from gymfg_il.learning.data_checks import check_trainable
    from gymfg_il.learning.saving import check_diverged, save_run
    from gymfg_il.policies.checkpoint_folder import check_out
    from gymfg_il.policies.configuration_vision import VisionConfig
    from gymfg_il.policies.factory import PolicyConfig, make_config, make_policy

    device = resolve_device(cfg.device)
    camera = cfg.camera if cfg.policy == "vision" else None
    if frames is None or (camera is not None and frames.camera != camera):
        frames = load_frames(cfg.dataset, camera)
    check_tasks(frames.episodes, cfg.mixed_tasks)
    shown = frames.demonstrated()  # of a policy's own flying, only a person's takeovers
    if len(shown) < len(frames):
        log.info(
            "%d of %d frames a policy flew unaided are left out",
            len(frames) - len(shown),
            len(frames),
        )
    if len(shown) == 0:
        raise ConfigError(
            f"{cfg.dataset}: every frame was flown by a policy and nobody took over, so there "
            "is nothing to learn from; add demonstrations (collect autopilot or manual)"
        )
    frames = shown
    check_trainable(frames, cfg.dataset)
    flight, why = frames.flight()
    if flight is None:
        log.warning(
            "the policy records no flight spec: %s; eval will need --task and --aircraft", why
        )
    label = flight.task_label if flight else "task"
    name = f"bc-{label}-{flight.aircraft if flight else 'aircraft'}-{cfg.policy}"
    out = Path(cfg.out) if cfg.out is not None else Path("policies") / name
    check_out(out)  # before training, not after
    train, val = split_by_episode(frames, cfg.val_fraction, cfg.seed)
    torch.manual_seed(cfg.seed)
    sequence: int | None = None
    chunks: tuple[int, int] | None = None
    stack: int | None = None
    pool = 1
    pconf: PolicyConfig
    if cfg.policy == "vision":
        assert frames.images is not None
        pconf = VisionConfig.for_observation(
            list(frames.observation_names),
            _observation_high(flight),
            camera=cfg.camera,
            image_size=int(frames.images.shape[1]),
            frames=cfg.frames,
            hidden=list(cfg.hidden),
            dt=1.0 / frames.fps,
        )
        stack, pool = cfg.frames, pconf.pool
    elif cfg.policy == "gru":
        pconf = make_config("gru", hidden=cfg.hidden[0], sequence_length=cfg.sequence_length)
        sequence = cfg.sequence_length
    elif cfg.policy == "chunk":
        pconf = make_config("chunk", hidden=list(cfg.hidden), history=cfg.history, chunk=cfg.chunk)
        chunks = (cfg.history, cfg.chunk)
    else:
        pconf = make_config("mlp", hidden=list(cfg.hidden))
    policy = make_policy(pconf, frames.obs_stats, frames.action_stats).to(device)
    policy.obs_noise = cfg.obs_noise
    batches = TensorBatches(train, cfg.batch_size, device, sequence, cfg.seed, chunks, stack, pool)
    val_batches = None
    if val:
        try:
            val_batches = TensorBatches(val, 1024, device, sequence, cfg.seed, chunks, stack, pool)
        except ConfigError as err:  # held-out frames too short for a window: train on
            log.warning("no validation loss: the held-out episodes are too short (%s)", err)
    image_size = None if frames.images is None else int(frames.images.shape[1])
    # the batches hold the pooled frames: the full-size ones of the split go (vision DAgger
    # on 60 episodes ran out of 24 GiB with them kept)
    for part in (train, val):
        if part is not None and part is not frames:  # frames may be the caller's
            part.images = None
    opt = torch.optim.AdamW(policy.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    epochs = epochs_for(cfg, frames)
    steps = epochs * len(batches)
    sched = torch.optim.lr_scheduler.LambdaLR(
        opt, lambda s: 0.05 + 0.95 * 0.5 * (1 + math.cos(math.pi * min(s, steps) / steps))
    )
    train_loss, val_loss = [], []
    settings = f"lr={cfg.lr}, weight_decay={cfg.weight_decay}, obs_noise={cfg.obs_noise}"
    started = time.perf_counter()
    for epoch in range(epochs):
        policy.train()
        total, count = 0.0, 0
        for obs, act in batches:
            loss = policy.loss(obs, act)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            sched.step()
            total += float(loss.detach()) * len(act)
            count += len(act)
        train_loss.append(total / count)
        if not math.isfinite(train_loss[-1]):
            check_diverged(policy, settings, epoch)
        val_loss.append(evaluate_loss(policy, val_batches) if val_batches else math.nan)
        if on_epoch is not None:
            on_epoch(epoch, train_loss[-1], val_loss[-1])
    seconds = time.perf_counter() - started
    meta = {
        "name": name,
        # what the policy flies: the whole spec, and its names for a reader of the file
        "spec": flight.to_dict() if flight else None,
        "spec_note": why,
        "task": flight.task if flight else None,
        "dynamic": flight.dynamic if flight else False,
        "aircraft": flight.aircraft if flight else None,
        "observation_names": frames.observation_names,
        "camera": {"view": cfg.camera, "size": image_size}
        if cfg.policy == "vision" and image_size is not None
        else None,
        "action_names": frames.action_names,
        "fps": frames.fps,
        "dataset": str(cfg.dataset),
        "train": {
            **{k: (str(v) if isinstance(v, Path) else v) for k, v in asdict(cfg).items()},
            "device": device,
            "epochs": epochs,
            "train_frames": len(train),  # not "frames": that is the camera stack
            "val_frames": len(val) if val else 0,
            "train_loss": train_loss,
            "val_loss": val_loss,
            "seconds": seconds,
        },
    }
    check_diverged(policy, settings)
    stats = (frames.obs_stats, frames.action_stats)
    save_run(out, policy.cpu(), meta, stats, (train_loss, val_loss))
    return TrainResult(out, train_loss, val_loss, seconds, len(train) * epochs, meta)


def evaluate_loss(policy: Any, batches: Any) -> float:
    import torch

    policy.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for obs, act in batches:
            total += float(policy.loss(obs, act)) * len(act)
            count += len(act)
    return total / count


def _observation_high(flight: FlightSpec | None) -> list[float] | None:
    """The upper observation bounds of ``flight``'s task (where its integrals saturate), or
    None for a dataset without a flight spec."""
    if flight is None:
        return None
    try:
        task = flight.solo_aircraft.task_factory()()
    except ConfigError:  # a spec of several aircraft: the policy saturates nothing
        return None
    return [float(v) for v in task.observation_bounds()[1]]
