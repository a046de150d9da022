"""Configuration of the vision policy: camera frames and the task's targets in, action out."""

from __future__ import annotations

from dataclasses import dataclass, field

from gymfg_il.errors import ConfigError

VIEWS = ("front", "chase")


@dataclass
class VisionConfig:
    """A small CNN over the last ``frames`` camera frames, joined with the task's target
    values (the observation entries named ``*_target``), then an MLP to the action.

    The aircraft's own state comes from the pictures alone: attitude from the horizon,
    height and motion from the ground's texture, rates from the difference of the frames.
    While training, the encoder also learns to name that state: a head estimates the
    observation entries the pictures show (``aux_names``: all but the targets and the error
    integrals) from the encoder's features, its error is added to the loss (``aux_weight``),
    and its estimate feeds the action head. In flight the policy still sees only the camera
    and the targets.

    An error integral (``*_error_integral``) is in no picture. The policy can keep its own
    (``memory_*``: in flight it sums its estimate of the error times ``dt``), but training does
    not use it: trained on the true integrals, or on sums of its own estimates, the policy
    flew roll at 52-56 % of the controller's return; without, 77-82 %, with steady errors of
    1.1-1.2 deg although its roll estimate was within 0.33 deg (40 demonstrations, 12
    held-out episodes). That is below the 90 % target; see the README.

    Attributes:
        camera: the view the policy sees (``front`` or ``chase``), as the dataset's
            ``observation.images.<camera>`` and the env's camera draw it.
        image_size: side of the square frames (the dataset's).
        frames: frames the policy sees: the current one and ``frames - 1`` before it (at an
            episode's start the first is repeated).
        pool: frames are averaged down by this factor before the convolutions (128 px -> 64).
        channels: output channels of the stride-2 convolutions.
        hidden: widths of the MLP after the encoder.
        state_names, state_index: the observation entries the policy reads besides the
            camera (filled in by training: the task's targets).
        aux_names, aux_index: the observation entries the encoder learns to estimate
            (filled in by training).
        aux_weight: weight of the estimate's error in the training loss (0: no estimate).
        memory_names, memory_index: the error integrals the policy keeps (filled in by
            training); memory_source: for each, its error's position in ``aux_names``.
        dt: the agent step (s) the integrals are summed over (the dataset's 1 / fps).
    """

    type: str = "vision"
    camera: str = "front"
    image_size: int = 128
    frames: int = 2
    pool: int = 2
    channels: list[int] = field(default_factory=lambda: [16, 32, 32, 32])
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    state_names: list[str] = field(default_factory=list)
    state_index: list[int] = field(default_factory=list)
    aux_names: list[str] = field(default_factory=list)
    aux_index: list[int] = field(default_factory=list)
    aux_weight: float = 1.0
    memory_names: list[str] = field(default_factory=list)
    memory_index: list[int] = field(default_factory=list)
    memory_source: list[int] = field(default_factory=list)
    dt: float = 0.1

    def __post_init__(self) -> None:
        problems = []
        if self.camera not in VIEWS:
            problems.append(f"camera={self.camera!r}: choose one of {VIEWS}")
        if self.frames < 1 or self.pool < 1:
            problems.append(f"frames={self.frames} and pool={self.pool} must be >= 1")
        side = self.image_size // self.pool // 2 ** len(self.channels)
        if self.image_size % self.pool or side < 1:
            problems.append(
                f"image_size={self.image_size} pooled by {self.pool} and halved "
                f"{len(self.channels)} times leaves nothing; use fewer channels or less pooling"
            )
        if not self.hidden or min(self.hidden) < 1 or not self.channels or min(self.channels) < 1:
            problems.append("hidden and channels must be non-empty lists of widths >= 1")
        if len(self.state_names) != len(self.state_index) or len(self.aux_names) != len(
            self.aux_index
        ):
            problems.append("each of state_* and aux_* must have names and indices alike")
        if not self.aux_weight >= 0:
            problems.append(f"aux_weight={self.aux_weight} must be >= 0")
        if problems:
            raise ConfigError("VisionConfig: " + "; ".join(problems))
