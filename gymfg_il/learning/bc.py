"""Behaviour cloning: regress the demonstrator's action from what the policy sees.

``train_bc`` takes the run's settings (``learning.config.TrainConfig``) through the same
steps for every policy type: the demonstrated frames (``learning.data``), the policy built
from its configuration for that data (``policies.factory``), the samples its window declares
(``learning.batches``), the optimisation (``learning.fit``) and the saved policy folder
(``learning.saving``)."""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gymfg_il.errors import ConfigError
from gymfg_il.learning.config import TrainConfig, epochs_for, resolve_device
from gymfg_il.policies.memory import NAMES as MEMORY_NAMES

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.learning.fit import Estimate
    from gymfg_il.learning.frames import Frames
    from gymfg_il.policies.window import Window

# validation over training loss above which train says the policy memorised its
# demonstrations: a weak signal, kept for the case it was made for, demonstrations without
# noise (the ratios measured: docs/results/defaults.md, "The memorisation warning")
OVERFIT_RATIO = 30.0
log = logging.getLogger(__name__)


@dataclass
class TrainResult:
    out: Path
    train_loss: list[float]
    val_loss: list[float]
    seconds: float
    frames: int
    meta: dict[str, Any]
    # every demonstration was flown with DART noise: the warning's remedy is applied already,
    # and the ratio reads what the task does not observe (the start airspeed the autopilot's
    # throttle holds: 60x on roll from 20 demonstrations, which flew every held-out episode)
    noised: bool = False

    @property
    def overfit(self) -> str:
        """A warning when the held-out episodes' loss is far above the training loss (the
        policy memorised its demonstrations), else "" (always "" when every demonstration
        was flown with DART noise)."""
        train, val = self.train_loss[-1], self.val_loss[-1]
        if self.noised or math.isnan(val) or val <= OVERFIT_RATIO * train or val < 1e-3:
            return ""
        return (
            f"validation loss {val:.4f} is {val / train:.1f}x the training loss {train:.4f}: "
            "the policy fits its demonstrations far better than episodes it has not seen, so "
            "it may not recover from its own deviations. More demonstrations help; so do "
            "DART noise for autopilot ones (collect autopilot --noise, the task's own by "
            "default: 0.1, the heading's and the turn's 0.2), `collect dagger`, and a person "
            "taking over from the policy (collect manual --assist)"
        )


def train_bc(
    cfg: TrainConfig,
    on_epoch: Callable[[int, float, float], None] | None = None,
    frames: Frames | None = None,
    on_start: Callable[[Estimate], None] | None = None,
) -> TrainResult:
    """Train, save the checkpoint and a loss-curve plot under ``cfg.out``. ``frames``: the
    dataset already in memory (else it is loaded); ``on_start`` is given an estimate of the
    run's time before it starts (a few batches timed on a copy of the policy, which changes
    nothing the run learns); ``on_epoch`` the losses after every epoch."""
    import torch

    threads = torch.get_num_threads()
    if resolve_device(cfg.device) == "cpu" and cfg.threads_wanted > 0:
        torch.set_num_threads(cfg.threads_wanted)
    try:
        return _train(cfg, on_epoch, frames, on_start)
    finally:
        torch.set_num_threads(threads)  # the caller's setting, as it was


def _train(
    cfg: TrainConfig,
    on_epoch: Callable[[int, float, float], None] | None,
    frames: Frames | None,
    on_start: Callable[[Estimate], None] | None,
) -> TrainResult:
    from gymfg_il.learning.data import split_by_episode
    from gymfg_il.learning.fit import Steps, estimate, fit
    from gymfg_il.learning.saving import check_diverged, finite_or_null, save_run

    device = resolve_device(cfg.device)
    window = cfg.policy.window
    given = frames
    shift: dict[str, Any] = {}
    frames = demonstrations(cfg, frames, window.camera, shift)
    flight, why = frames.flight()
    name, out = _destination(cfg, flight, why)
    train, val = split_by_episode(frames, cfg.val_fraction, cfg.seed)
    image_size = None if frames.images is None else int(frames.images.shape[1])
    policy = _policy(cfg, frames, flight, image_size, device)
    batches, val_batches = _batches(train, val, cfg, window, device)
    # the batches hold the pooled camera frames: the full-size ones of the split go (vision
    # DAgger on 60 episodes ran out of memory with them kept), but the caller's
    for part in (train, val):
        if part is not None and part is not given:
            part.images = None
    steps = Steps(epochs_for(cfg, frames), cfg.lr, cfg.weight_decay)
    if on_start is not None:
        on_start(estimate(policy, steps, batches, val_batches))
    settings = f"lr={cfg.lr}, weight_decay={cfg.weight_decay}, obs_noise={cfg.obs_noise}"
    started = time.perf_counter()
    train_loss, val_loss = fit(policy, steps, batches, val_batches, settings, on_epoch)
    seconds = time.perf_counter() - started
    run = {
        "device": device,
        "epochs": steps.epochs,
        "train_frames": len(train),  # not "frames": a vision policy's setting once
        "val_frames": len(val) if val else 0,
        "train_loss": train_loss,
        "val_loss": finite_or_null(val_loss),
        "seconds": seconds,
        **shift,
    }
    meta = run_meta(cfg, name, frames, flight, why, image_size, run)
    check_diverged(policy, settings)
    stats = (frames.obs_stats, frames.action_stats)
    save_run(out, policy.cpu(), meta, stats, (train_loss, val_loss))
    noised = all(float(n or 0.0) > 0 for n in frames.episodes.get("gymfg/noise") or [0.0])
    frames_seen = len(train) * steps.epochs
    return TrainResult(out, train_loss, val_loss, seconds, frames_seen, meta, noised)


def _destination(cfg: TrainConfig, flight: FlightSpec | None, why: str) -> tuple[str, Path]:
    """The policy's name (task, aircraft, type) and the folder it is saved to (``cfg.out``,
    else an unused one under policies/), checked before training rather than after."""
    from gymfg_il.policies.checkpoint_folder import check_out

    if flight is None:
        log.warning(
            "the policy records no flight spec: %s; eval will need --task and --aircraft", why
        )
    name = f"bc-{flight.task_label if flight else 'task'}-"
    name += f"{flight.aircraft if flight else 'aircraft'}-{cfg.policy.type}"
    out = Path(cfg.out) if cfg.out is not None else unused(Path("policies") / name)
    check_out(out)  # before training, not after
    return name, out


def _policy(
    cfg: TrainConfig,
    frames: Frames,
    flight: FlightSpec | None,
    image_size: int | None,
    device: str,
) -> Any:
    """The policy ``cfg`` configures, made for the data of ``frames`` (its observations,
    rate, flight and camera size) and seeded with ``cfg.seed``, on ``device``."""
    import torch

    from gymfg_il.learning.memory import by_expert
    from gymfg_il.policies.configuration import DatasetInfo
    from gymfg_il.policies.factory import make_policy

    data = DatasetInfo(list(frames.observation_names), frames.fps, flight, image_size)
    config = cfg.policy.for_data(data)
    torch.manual_seed(cfg.seed)
    policy = make_policy(config, frames.obs_stats, frames.action_stats).to(device)
    policy.obs_noise = cfg.obs_noise
    if hasattr(policy, "anchor_memory") and by_expert(frames):
        policy.anchor_memory()
    return policy


def unused(folder: Path) -> Path:
    """``folder``, or where it holds something already, the first of ``folder-2``,
    ``folder-3``, ... that does not exist: a default ``--out`` never replaces an earlier
    policy (an explicit one does, as asked)."""
    found, k = folder, 1
    while found.exists() or found.is_symlink():
        k += 1
        found = folder.with_name(f"{folder.name}-{k}")
    if found != folder:
        log.warning(
            "%s holds an earlier policy: this one goes to %s (--out chooses)", folder, found
        )
    return found


def demonstrations(
    cfg: TrainConfig,
    frames: Frames | None,
    camera: str | None,
    record: dict[str, Any] | None = None,
) -> Frames:
    """The frames to learn from: the dataset's (``frames``, or loaded with ``camera``'s
    frames), checked to be of one task and finite, selected, shifted by the pilot's reaction
    (``cfg.shift``: what was shifted goes into ``record``), from each pilot's first input,
    less what a policy flew unaided."""
    from gymfg_il.learning.data import check_tasks, load_frames
    from gymfg_il.learning.data_checks import check_trainable
    from gymfg_il.learning.memory import remembered
    from gymfg_il.learning.selection import once_each, selected

    if frames is None or (camera is not None and frames.camera != camera):
        frames = load_frames(cfg.dataset, camera)
    check_tasks(frames.episodes, cfg.mixed_tasks)
    frames = remembered(frames, cfg.policy)  # each episode whole, before frames are left out
    frames = selected(once_each(frames, cfg.dataset), cfg.select, cfg.dataset)
    if cfg.shift != "0":
        from gymfg_il.learning.reaction import shifted

        frames, shift = shifted(frames, cfg.shift)
        if record is not None:
            record.update(shift)
    if not cfg.before_first_input:
        started = frames.from_first_input()
        if len(started) < len(frames):
            log.info(
                "%d frames before the pilots' first inputs are left out", len(frames) - len(started)
            )
        frames = started
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
    check_trainable(shown, cfg.dataset)
    return shown


def _batches(
    train: Frames, val: Frames | None, cfg: TrainConfig, window: Window, device: str
) -> tuple[Any, Any]:
    """The training batches and the validation batches (None where there are no held-out
    episodes, or they are too short for a window)."""
    from gymfg_il.learning.batches import TensorBatches
    from gymfg_il.learning.selection import grade_weights

    weights = grade_weights(train, cfg.dataset) if cfg.weight == "grade" else None
    batches = TensorBatches(train, cfg.batch_size, device, cfg.seed, window, weights)
    val_batches = None
    if val:
        try:
            val_batches = TensorBatches(val, 1024, device, cfg.seed, window)
        except ConfigError as err:  # held-out frames too short for a window: train on
            log.warning("no validation loss: the held-out episodes are too short (%s)", err)
    return batches, val_batches


def run_meta(
    cfg: TrainConfig,
    name: str,
    frames: Frames,
    flight: FlightSpec | None,
    why: str,
    image_size: int | None,
    run: dict[str, Any],
) -> dict[str, Any]:
    """What config.json records beside the policy: what it flies (the whole flight spec,
    and its names for a reader of the file), its data, and the run (``cfg``'s settings but
    the policy's own, which config.json keeps under ``policy``, and ``run``)."""
    camera = cfg.policy.window.camera
    settings = {f.name: getattr(cfg, f.name) for f in fields(cfg)}
    settings["policy"] = cfg.policy.type
    return {
        "name": name,
        "spec": flight.to_dict() if flight else None,
        "spec_note": why,
        "task": flight.task if flight else None,
        "dynamic": flight.dynamic if flight else False,
        "aircraft": flight.aircraft if flight else None,
        # what the env gives; a memory's own columns are the policy's (``memory_names``)
        "observation_names": [n for n in frames.observation_names if n not in MEMORY_NAMES],
        "memory_names": [n for n in frames.observation_names if n in MEMORY_NAMES],
        "camera": {"view": camera, "size": image_size} if camera and image_size else None,
        "action_names": frames.action_names,
        "fps": frames.fps,
        "dataset": str(cfg.dataset),
        "train": {k: str(v) if isinstance(v, Path) else v for k, v in settings.items()} | run,
    }
