"""What a policy learns from around each training frame: its ``Window``, declared by its
configuration (as LeRobot's configurations declare their delta indices), so the data pipeline
(``learning.batches``) gathers every policy's samples the same way; and ``pool_frames``, the
camera-frame averaging that training and flight both apply."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Window:
    """The frames of one training sample, as offsets from its frame ``t`` (``-1`` is the frame
    before, ``0`` the frame itself). ``None`` is frame ``t`` alone, without a time axis.

    A sample never reaches across a stretch of consecutive frames of one episode (a person's
    takeovers leave gaps in an episode): where ``pad`` is set, an offset outside the stretch
    takes its first or last frame for observations and camera frames, and NaN for actions (the
    loss leaves those out); where it is not, only the samples that lie whole inside a stretch
    are drawn (a recurrent policy's training windows).

    Attributes:
        observation: offsets of the observations (``observation.state``) the policy reads.
        action: offsets of the actions it predicts.
        images: offsets of the camera frames it sees (``camera`` names the view).
        camera: the dataset's camera (``observation.images.<camera>``), or None.
        pool: camera frames are averaged over ``pool`` x ``pool`` pixels, once for the
            dataset (``pool_frames``).
        pad: pad samples at a stretch's edges (see above) rather than leave them out.
    """

    observation: tuple[int, ...] | None = None
    action: tuple[int, ...] | None = None
    images: tuple[int, ...] | None = None
    camera: str | None = None
    pool: int = 1
    pad: bool = True

    def __post_init__(self) -> None:
        for name in ("observation", "action", "images"):
            offsets = getattr(self, name)
            if offsets is not None:
                assert len(offsets) > 0, f"{name}: give offsets or None"
                object.__setattr__(self, name, tuple(int(o) for o in offsets))
        assert (self.images is None) == (self.camera is None), "images need a camera"
        assert self.pool >= 1

    @property
    def span(self) -> int:
        """Consecutive frames one sample covers (1 for frame ``t`` alone)."""
        offsets = [0]
        for part in (self.observation, self.action, self.images):
            offsets += part or ()
        return max(offsets) - min(offsets) + 1

    def describe(self) -> str:
        """One line on what a sample holds, for the estimate printed before training."""
        parts = []
        if self.observation is not None and len(self.observation) > 1:
            steps = len(self.observation)
            if self.pad:
                parts.append(f"{steps} observations")
            else:
                parts.append(f"windows of {steps} steps, each frame in up to {steps}")
        if self.action is not None and len(self.action) > 1 and self.action != self.observation:
            parts.append(f"{len(self.action)} actions")
        if self.images is not None:
            parts.append(f"{len(self.images)} {self.camera} camera frame(s)")
        return ", ".join(parts) or "one frame each"


def pool_frames(frames: Any, pool: int) -> Any:
    """Frames (..., H, W, 3) uint8 (a torch tensor) averaged over ``pool`` x ``pool`` blocks
    and rounded back to uint8: done once to a dataset's frames before training, and to every
    frame in flight, so both see the same pixels (and training gathers 1 / pool^2 of the
    bytes)."""
    import torch

    if pool == 1:
        return frames
    *lead, h, w, c = frames.shape
    blocks = frames.reshape(*lead, h // pool, pool, w // pool, pool, c).float()
    return blocks.mean(dim=(-4, -2)).round().to(torch.uint8)
