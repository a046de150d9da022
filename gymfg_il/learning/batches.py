"""Training samples as shuffled batches of in-memory tensors, gathered by indexing (no
per-item Python), the same way for every policy: each policy's configuration declares the
frames one sample holds around its frame (``policies.window.Window``), and here those
offsets become index arrays, once, and every batch is one gather per input."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.learning.frames import Frames
from gymfg_il.policies.window import Window, pool_frames


def stretches(frames: Frames) -> tuple[np.ndarray, np.ndarray]:
    """For every frame, the index of the first and of the last frame of its stretch: a run of
    consecutive frames of one episode (a takeover dataset has gaps)."""
    n = len(frames)
    breaks = np.ones(n, bool)
    breaks[1:] = (frames.episode[1:] != frames.episode[:-1]) | (
        frames.frame[1:] != frames.frame[:-1] + 1
    )
    first_of = np.flatnonzero(breaks)
    stretch = np.cumsum(breaks) - 1
    return first_of[stretch], np.append(first_of[1:] - 1, n - 1)[stretch]


def window_indices(frames: Frames, offsets: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """For every frame ``t``: the indices of frames ``t + offsets`` held inside ``t``'s
    stretch (an offset before its start takes its first frame, one past its end its last),
    and which of them lie inside it."""
    first, last = stretches(frames)
    wanted = np.arange(len(frames))[:, None] + np.asarray(offsets)
    inside = (wanted >= first[:, None]) & (wanted <= last[:, None])
    return np.clip(wanted, first[:, None], last[:, None]), inside


class TensorBatches:
    """Shuffled batches of the samples ``window`` declares, as tensors on ``device``:
    ``(inputs, action)``, where ``inputs`` is the observations (or, for a window with camera
    frames, ``(frames, observations)``) and each has a time axis where the window gives
    offsets for it. Actions outside a sample's stretch are NaN; where the window does not
    pad, only samples that lie whole inside a stretch are drawn. With ``weights`` (one per
    frame) an epoch draws as many samples as there are, with replacement, each in proportion
    to its frame's weight."""

    def __init__(
        self,
        frames: Frames,
        batch_size: int,
        device: str = "cpu",
        seed: int = 0,
        window: Window | None = None,
        weights: np.ndarray | None = None,
    ) -> None:
        import torch

        self.torch = torch
        self.batch_size = batch_size
        self.window = window = window or Window()
        self.obs = torch.as_tensor(frames.obs, device=device)
        self.action = torch.as_tensor(frames.action, device=device)
        self.images: Any = None
        if window.images is not None:
            if frames.images is None:
                raise ConfigError(
                    f"the policy sees the {window.camera} camera, and the frames given have "
                    "none: load them with it (load_frames(root, camera))"
                )
            images = torch.as_tensor(frames.images)
            parts = range(0, len(images), 4096)  # pooled a part at a time: less memory
            self.images = torch.cat([pool_frames(images[i : i + 4096], window.pool) for i in parts])
            self.images = self.images.to(device)
        self.index: dict[str, Any] = {}  # per input with offsets: (frames, offsets) indices
        whole = np.ones(len(frames), bool)  # the samples that lie whole inside their stretch
        for name in ("observation", "action", "images"):
            offsets = getattr(window, name)
            if offsets is None:
                continue
            at, within = window_indices(frames, offsets)
            self.index[name] = torch.as_tensor(at, device=device)
            whole &= within.all(axis=1)
            if name == "action":
                self.outside = torch.as_tensor(~within, device=device)
        starts = np.arange(len(frames)) if window.pad else np.flatnonzero(whole)
        if len(starts) == 0:
            raise ConfigError(
                f"no episode (nor, in a takeover dataset, a person's takeover) is "
                f"{window.span} steps long, as each of the policy's training windows is; "
                "train it on shorter windows"
            )
        self.starts = torch.as_tensor(starts, device=device)
        self.generator = torch.Generator(device="cpu").manual_seed(seed)
        self.weights = None if weights is None else torch.as_tensor(weights[starts])

    def __len__(self) -> int:
        return (len(self.starts) + self.batch_size - 1) // self.batch_size

    def __iter__(self) -> Iterator[tuple[Any, Any]]:
        yield from self._batches(self.order())

    def order(self) -> Any:
        """One epoch's samples as frame indices: shuffled, or drawn by weight."""
        torch, n = self.torch, len(self.starts)
        if self.weights is None:
            order = torch.randperm(n, generator=self.generator)
        else:
            order = torch.multinomial(self.weights, n, replacement=True, generator=self.generator)
        return self.starts[order.to(self.starts.device)]

    def first(self, count: int) -> Iterator[tuple[Any, Any]]:
        """The first ``count`` batches in frame order, drawing nothing from the shuffle."""
        return self._batches(self.starts[: count * self.batch_size])

    def _batches(self, order: Any) -> Iterator[tuple[Any, Any]]:
        for i in range(0, len(order), self.batch_size):
            yield self.sample(order[i : i + self.batch_size])

    def sample(self, starts: Any) -> tuple[Any, Any]:
        """The samples of the frames ``starts`` (indices into the frames)."""
        index = self.index
        obs = self.obs[index["observation"][starts]] if "observation" in index else self.obs[starts]
        if "action" in index:
            action = self.action[index["action"][starts]]
            action[self.outside[starts]] = float("nan")
        else:
            action = self.action[starts]
        if self.images is None:
            return obs, action
        return (self.images[index["images"][starts]], obs), action
