"""Training a vision policy's memory the way it is flown.

A vision policy keeps the error integrals the task observes (``*_error_integral``) by
summing its own estimate of the error, since no picture shows them
(``policies.configuration_vision``). Trained on the true integrals, it met in flight
integrals that drifted with its estimate's small bias, far outside what it had learned
(roll: steady errors of 11 deg). So after a few epochs the integrals it trains on are
replaced, every epoch, by the sums of its current estimates over each episode: the same
quantity it will be given in flight.
"""

from __future__ import annotations

from typing import Any

import numpy as np

WARM_EPOCHS = 3  # epochs on the true integrals before the estimates are good enough to sum


def refresh_memory(policy: Any, batches: Any, starts: np.ndarray) -> None:
    """Overwrite the memory columns of ``batches.obs`` (a ``TensorBatches`` of a vision
    policy, frames in episode order) with the running sums of the policy's own estimated
    errors; ``starts[i]``: frame i is the first of its stretch."""
    import torch

    memory = policy.memory_index
    if len(memory) == 0:
        return
    was_training = policy.training
    policy.eval()
    errors = []
    source = policy.aux_index[policy.memory_source]
    with torch.no_grad():
        for i in range(0, len(batches.obs), 2048):
            images = batches.images[batches.past[i : i + 2048]]
            _, estimate = policy._forward(images, batches.obs[i : i + 2048])
            raw = estimate[:, policy.memory_source] * policy.obs_norm.std[source]
            errors.append(raw + policy.obs_norm.mean[source])
    step = torch.cat(errors).double() * policy.config.dt
    total = torch.cumsum(step, dim=0)
    first = torch.as_tensor(np.flatnonzero(starts), device=total.device)
    owner = torch.as_tensor(np.cumsum(starts) - 1, device=total.device)
    before = (total[first] - step[first])[owner]
    batches.obs[:, memory] = (total - before).to(batches.obs.dtype)
    policy.train(was_training)


def stretch_starts(frames: Any) -> np.ndarray:
    """Whether each frame begins a run of consecutive frames of one episode."""
    starts = np.ones(len(frames), bool)
    starts[1:] = (frames.episode[1:] != frames.episode[:-1]) | (
        frames.frame[1:] != frames.frame[:-1] + 1
    )
    return starts
