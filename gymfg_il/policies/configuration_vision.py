"""Configuration of the vision policy: camera frames, the task's targets and its instruments
in, action out."""

from __future__ import annotations

from dataclasses import dataclass, field

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import INDEX

VIEWS = ("front", "chase")
# the aircraft's state that no frame shows: the ground's checkerboard looks the same every
# 90 degrees of heading, so the heading comes from the compass, as a pilot's does
INSTRUMENTS = frozenset({"heading_deg"})
# what stays as it is when the aircraft rolls about its forward axis (the front camera's
# optical axis): Euler pitch and heading, height, speeds, the roll rate, the position
ROLL_INVARIANT = frozenset(
    {"altitude_ft", "vertical_speed_fps", "pitch_deg", "heading_deg", "airspeed_kts",
     "p_rad_s", "lat_deg", "lon_deg"}
)  # fmt: skip


def seen_for(names: list[str]) -> list[str]:
    """The observation entries a vision policy estimates from its camera: the aircraft's own
    state (attitude, height, speeds, rates: ``sim.properties`` variables) but its heading
    (``INSTRUMENTS``). Some the camera shows well (attitude from the horizon, height from
    the ground's texture), some hardly (an angle of attack): the hands learn how far to
    trust each. What else a task observes is given, not seen (``VisionConfig``)."""
    return [n for n in names if n in INDEX and n not in INSTRUMENTS]


@dataclass
class VisionConfig:
    """A pilot's eye and a pilot's hands, trained together by behaviour cloning.

    The eye is a small CNN over the last ``frames`` camera frames that estimates the
    aircraft's state the task observes (``seen_names``: attitude, height, rates, speeds,
    as well as the camera shows each). The hands are an MLP that flies from those
    estimates, the task's targets (``target_names``), the errors to them and the errors'
    integrals, recomputed from the estimates in flight as the task computes them from the
    truth (``error_*``, ``integral_*``), and what else the task observes, given as the task
    gives it (``given_*``): its instruments, which a pilot flying by sight reads too (the
    compass's heading and the errors to a heading target, an approach's localizer and
    glidepath deviations, a waypoint's bearing and distance, the lead's offsets in a
    formation, the error to an altitude the task assigns without observing it, a turn's
    remaining degrees). Heading from the camera (as cosine and sine: a regression of 1 and
    359 degrees answers 180) flew the heading task at 15 % of the state policy's return,
    6 % success, 20 demonstrations: the ground looks the same every 90 degrees; from the
    compass, 101 % and 16 of 16. The hands never see the CNN's features: they learn
    from the demonstrated states, with the noise the eye makes (its running error on the
    training frames, times ``noise_scale``) added to the states it estimates, and the eye
    learns from the frames, so each generalises as a state policy and a regression do.

    End to end (the CNN's features straight into the action head) the policy flew roll at
    63-82 % of the controller's return with 0-3 crashes in 16: the demonstrator's error
    integral is in no picture, and a head reading features overfits the frames it saw. Split
    this way it flies roll at 97.5-99.2 % of the state policy's return (20-60 demonstrations,
    16 held-out episodes each, no crash; README, "Seeing").

    Attributes:
        camera: the view the policy sees (``front`` or ``chase``), as the dataset's
            ``observation.images.<camera>`` and the env's camera draw it.
        image_size: side of the square frames (the dataset's).
        frames: frames the policy sees: the current one and ``frames - 1`` before it (at an
            episode's start the first is repeated).
        pool: frames are averaged down by this factor before the convolutions (128 px -> 64).
        channels: output channels of the stride-2 convolutions.
        hidden: widths of the hands' MLP.
        seen_names, seen_index: observation entries the eye estimates (filled in by
            training: ``seen_for``).
        target_names, target_index: the task's targets, read from the observation.
        error_names, error_index: the errors to the targets (``<variable>_error``), computed
            in flight as target minus estimate; error_seen, error_target: for each, its
            variable's position in ``seen_names`` and its target's in ``target_names``.
        integral_names, integral_index: the errors' integrals (``<error>_integral``), summed
            in flight over ``dt``; integral_error: for each, its error's position in
            ``error_names``; integral_limit: where the task saturates each (its observation
            bound; 0: none known, no limit).
        given_names, given_index: the rest of the observation, read as it is.
        aux_weight: weight of the eye's error in the training loss.
        roll_augment_deg: the front camera rolls with the aircraft about its optical axis,
            so a frame rotated by an angle is the frame of a roll that much larger: while
            training, ``augment_share`` of the eye's frame stacks are rotated by an angle
            drawn up to this many degrees either way and their roll label moved with it
            (entries a roll changes other than the roll itself, such as an angle of attack,
            are left out of those samples' loss; ``ROLL_INVARIANT`` are kept). Roll from 20
            demonstrations: the eye's held-out error fell from 1.37 to 0.17 deg. 0: off;
            the chase camera does not roll, and is never rotated.
        augment_share: the share of frame stacks rotated.
        noise_scale: the states the hands learn from carry the eye's running error times this.
        dt: the agent step (s) the integrals are summed over (the dataset's 1 / fps).
    """

    type: str = "vision"
    camera: str = "front"
    image_size: int = 128
    frames: int = 2
    pool: int = 2
    channels: list[int] = field(default_factory=lambda: [16, 32, 32, 32])
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    seen_names: list[str] = field(default_factory=list)
    seen_index: list[int] = field(default_factory=list)
    target_names: list[str] = field(default_factory=list)
    target_index: list[int] = field(default_factory=list)
    error_names: list[str] = field(default_factory=list)
    error_index: list[int] = field(default_factory=list)
    error_seen: list[int] = field(default_factory=list)
    error_target: list[int] = field(default_factory=list)
    integral_names: list[str] = field(default_factory=list)
    integral_index: list[int] = field(default_factory=list)
    integral_error: list[int] = field(default_factory=list)
    integral_limit: list[float] = field(default_factory=list)
    given_names: list[str] = field(default_factory=list)
    given_index: list[int] = field(default_factory=list)
    aux_weight: float = 1.0
    roll_augment_deg: float = 15.0
    augment_share: float = 0.5
    noise_scale: float = 1.0
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
        pairs = ("seen", "target", "error", "integral", "given")
        if any(len(getattr(self, f"{p}_names")) != len(getattr(self, f"{p}_index")) for p in pairs):
            problems.append(f"each of {', '.join(p + '_*' for p in pairs)} needs names and indices")
        n_err = len(self.error_names)
        if not len(self.error_seen) == len(self.error_target) == n_err:
            problems.append("error_seen and error_target need one entry per error")
        if not len(self.integral_error) == len(self.integral_limit) == len(self.integral_names):
            problems.append("integral_error and integral_limit need one entry per integral")
        if not self.seen_names:
            problems.append("seen_names is empty: the camera must show the policy something")
        if not self.aux_weight > 0 or not self.noise_scale >= 0:
            problems.append(f"aux_weight={self.aux_weight} must be > 0, noise_scale >= 0")
        if not 0 <= self.roll_augment_deg <= 90 or not 0 <= self.augment_share <= 1:
            problems.append(
                f"roll_augment_deg={self.roll_augment_deg} must lie in [0, 90] and "
                f"augment_share={self.augment_share} in [0, 1]"
            )
        if problems:
            raise ConfigError("VisionConfig: " + "; ".join(problems))

    @classmethod
    def for_observation(
        cls, names: list[str], high: list[float] | None = None, **kwargs: object
    ) -> VisionConfig:
        """The config for a task observing ``names`` (``high``: the task's observation
        bounds, ``Task.observation_bounds``, where its integrals saturate): what the eye
        estimates, which errors and integrals the hands recompute from it, and what they
        are given."""
        seen = seen_for(names)
        targets = [n for n in names if n.endswith("_target")]
        errors = [
            n
            for n in names
            if n.endswith("_error")
            and n.removesuffix("_error") in seen
            and n.removesuffix("_error") + "_target" in targets
        ]
        integrals = [n for n in names if n.endswith("_integral") and n.removesuffix("_integral")
                     in errors]  # fmt: skip
        derived = set(seen) | set(targets) | set(errors) | set(integrals)
        given = [n for n in names if n not in derived]
        variables = [e.removesuffix("_error") for e in errors]
        limits = [float(high[names.index(n)]) if high is not None else 0.0 for n in integrals]
        return cls(
            seen_names=seen,
            seen_index=[names.index(n) for n in seen],
            target_names=targets,
            target_index=[names.index(n) for n in targets],
            error_names=errors,
            error_index=[names.index(n) for n in errors],
            error_seen=[seen.index(v) for v in variables],
            error_target=[targets.index(v + "_target") for v in variables],
            integral_names=integrals,
            integral_index=[names.index(n) for n in integrals],
            integral_error=[errors.index(n.removesuffix("_integral")) for n in integrals],
            integral_limit=limits,
            given_names=given,
            given_index=[names.index(n) for n in given],
            **kwargs,  # type: ignore[arg-type]
        )
