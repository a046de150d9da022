"""The optimisation of a behaviour-cloning run: AdamW with a cosine-decayed step size over
the run's batches, the training and validation loss of every epoch, and, before any of it,
an estimate of how long it will take from a few batches timed on a copy of the policy."""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gymfg_il.learning.saving import check_diverged

TIMED_BATCHES = 3  # timed for the estimate, after one that warms up


@dataclass(frozen=True)
class Steps:
    """How a run optimises: ``epochs`` passes, AdamW at ``lr`` (cosine-decayed to 5 % over
    the run) with ``weight_decay``."""

    epochs: int
    lr: float
    weight_decay: float

    def optimizer(self, policy: Any) -> Any:
        import torch

        return torch.optim.AdamW(policy.parameters(), lr=self.lr, weight_decay=self.weight_decay)

    def schedule(self, optimizer: Any, batches: int) -> Any:
        import torch

        steps = self.epochs * batches
        return torch.optim.lr_scheduler.LambdaLR(
            optimizer,
            lambda s: 0.05 + 0.95 * 0.5 * (1 + math.cos(math.pi * min(s, steps) / steps)),
        )


@dataclass(frozen=True)
class Estimate:
    """What a run will do and about how long it will take (``estimate``).

    Attributes:
        epochs: passes over the training samples.
        batches: training batches an epoch.
        val_batches: validation batches an epoch (0: no validation loss).
        batch_s: seconds a training batch took, timed.
        val_batch_s: seconds a validation batch took, timed.
    """

    epochs: int
    batches: int
    val_batches: int
    batch_s: float
    val_batch_s: float

    @property
    def seconds(self) -> float:
        return self.epochs * (self.batches * self.batch_s + self.val_batches * self.val_batch_s)


def estimate(policy: Any, steps: Steps, batches: Any, val_batches: Any) -> Estimate:
    """Time a few training batches (and one validation batch) on a copy of ``policy`` with
    an optimiser of its own, drawing nothing from ``batches``' shuffle and leaving torch's
    random state as it was: the run that follows learns what it would have learned
    without the estimate."""
    import torch

    trial = copy.deepcopy(policy)
    optimizer = steps.optimizer(trial)
    with torch.random.fork_rng(devices=_cuda_devices(trial)):
        timed = []
        for obs, act in batches.first(TIMED_BATCHES + 1):
            started = time.perf_counter()
            _step(trial, optimizer, obs, act)
            _synchronize(trial)
            timed.append(time.perf_counter() - started)
        val_s = 0.0
        if val_batches is not None:
            started = time.perf_counter()
            evaluate_loss(trial, val_batches.first(1))
            _synchronize(trial)
            val_s = time.perf_counter() - started
    batch_s = sum(timed[1:]) / len(timed[1:]) if len(timed) > 1 else timed[0]
    val_count = len(val_batches) if val_batches is not None else 0
    return Estimate(steps.epochs, len(batches), val_count, batch_s, val_s)


def fit(
    policy: Any,
    steps: Steps,
    batches: Any,
    val_batches: Any,
    settings: str,
    on_epoch: Callable[[int, float, float], None] | None = None,
) -> tuple[list[float], list[float]]:
    """Train ``policy`` for ``steps.epochs`` over ``batches``: the training and validation
    loss of every epoch (NaN without ``val_batches``). A loss that stops being finite ends
    the run (``DivergedError``, naming ``settings``)."""
    optimizer = steps.optimizer(policy)
    schedule = steps.schedule(optimizer, len(batches))
    train_loss: list[float] = []
    val_loss: list[float] = []
    for epoch in range(steps.epochs):
        policy.train()
        total, count = 0.0, 0
        for obs, act in batches:
            loss = _step(policy, optimizer, obs, act)
            schedule.step()
            total += float(loss.detach()) * len(act)
            count += len(act)
        train_loss.append(total / count)
        if not math.isfinite(train_loss[-1]):
            check_diverged(policy, settings, epoch)
        val_loss.append(evaluate_loss(policy, val_batches) if val_batches else math.nan)
        if on_epoch is not None:
            on_epoch(epoch, train_loss[-1], val_loss[-1])
    return train_loss, val_loss


def _step(policy: Any, optimizer: Any, obs: Any, act: Any) -> Any:
    loss = policy.loss(obs, act)
    optimizer.zero_grad(set_to_none=True)
    loss.backward()
    optimizer.step()
    return loss


def evaluate_loss(policy: Any, batches: Any) -> float:
    """The mean loss over ``batches`` (any iterable of ``(inputs, action)``), in eval mode."""
    import torch

    policy.eval()
    total, count = 0.0, 0
    with torch.no_grad():
        for obs, act in batches:
            total += float(policy.loss(obs, act)) * len(act)
            count += len(act)
    return total / count


def _cuda_devices(policy: Any) -> list[int]:
    return sorted({p.device.index or 0 for p in policy.parameters() if p.device.type == "cuda"})


def _synchronize(policy: Any) -> None:
    import torch

    if _cuda_devices(policy):
        torch.cuda.synchronize()
