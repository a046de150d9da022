"""Configuration of the vision policy: camera frames, the task's targets and its instruments
in, action out."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, ClassVar, Literal

from gymfg_il.errors import ConfigError
from gymfg_il.policies.configuration import DatasetInfo, PolicyConfig
from gymfg_il.policies.factory import register_policy
from gymfg_il.policies.window import Window
from gymfg_il.sim.properties import INDEX

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec

DERIVED = {"cli": False}  # filled in from the dataset (``for_data``), not given
# the aircraft's state that no frame shows: the ground's checkerboard looks the same every
# 90 degrees of heading, so the heading comes from the compass, as a pilot's does
INSTRUMENTS = frozenset({"heading_deg"})
# what stays as it is when the aircraft rolls about its forward axis (the front camera's
# optical axis): Euler pitch and heading, height, speeds, the roll rate, the position
ROLL_INVARIANT = frozenset(
    [
        "altitude_ft",
        "vertical_speed_fps",
        "pitch_deg",
        "heading_deg",
        "airspeed_kts",
        "p_rad_s",
        "lat_deg",
        "lon_deg",
    ]
)


def seen_for(names: list[str]) -> list[str]:
    """The observation entries a vision policy estimates from its camera: the aircraft's own
    state (attitude, height, speeds, rates: ``sim.properties`` variables) but its heading
    (``INSTRUMENTS``). Some the camera shows well (attitude from the horizon, height from
    the ground's texture), some hardly (an angle of attack): the hands learn how far to
    trust each. What else a task observes is given, not seen (``VisionConfig``)."""
    return [n for n in names if n in INDEX and n not in INSTRUMENTS]


@register_policy("vision", "gymfg_il.policies.modeling_vision:VisionPolicy")
@dataclass
class VisionConfig(PolicyConfig):
    """A CNN over the camera's last frames, with the task's targets and instruments (needs a
    dataset collected with --images).

    A pilot's eye and hands, trained together by behaviour cloning. The eye, a small CNN over
    the last ``frames`` camera frames, estimates the aircraft's state the task observes
    (``seen_for``: attitude, height, rates, speeds, as well as the camera shows each). The
    hands, an MLP, fly from those estimates, the task's targets, the errors to them and the
    errors' integrals (recomputed in flight from the estimates, as the task computes them
    from the truth), and the rest of the observation as the task gives it: the instruments a
    pilot flying by sight reads too (the compass and the errors to a heading target, an
    approach's deviations, a waypoint's bearing and distance, the lead's offsets in a
    formation). The hands never see the eye's features: they learn from the demonstrated
    states with the eye's running error added to what it estimates, and the eye learns from
    the frames.

    The ``*_names`` and ``*_index`` fields say which observation entries are seen, targets,
    errors (``<variable>_error``, recomputed as target minus estimate; ``error_seen`` and
    ``error_target`` place each error's variable in ``seen_names`` and its target in
    ``target_names``), integrals (``<error>_integral``, summed over ``dt``; ``integral_error``
    places each one's error, ``integral_limit`` is where the task saturates it, 0 for none)
    and given; training fills them in from the dataset (``for_observation``).

    Attributes:
        camera: the view the policy sees (the dataset's ``observation.images.<camera>``, as
            the env's camera draws it).
        image_size: side of the square frames (the dataset's).
        frames: camera frames the policy sees: the current one and ``frames - 1`` before it
            (at an episode's start the first is repeated; two show the rates).
        pool: frames are averaged down by this factor before the convolutions (128 px -> 64).
        channels: output channels of the stride-2 convolutions.
        hidden: widths of the hands' MLP.
        aux_weight: weight of the eye's error in the training loss.
        roll_augment_deg: the front camera rolls with the aircraft about its optical axis, so
            a frame rotated by an angle is the frame of a roll that much larger: while
            training, ``augment_share`` of the eye's frame stacks are rotated by an angle
            drawn up to this many degrees either way and their roll label moved with it
            (entries a roll changes other than the roll itself, such as an angle of attack,
            are left out of those samples' loss; ``ROLL_INVARIANT`` are kept). 0: off; the
            chase camera does not roll and is never rotated.
        augment_share: the share of frame stacks rotated.
        noise_scale: the states the hands learn from carry the eye's running error times this.
        dt: the agent step (s) the integrals are summed over (the dataset's 1 / fps).
    """

    default_threads: ClassVar[int] = 0  # the convolutions run faster on more than one
    max_default_epochs: ClassVar[int | None] = 20  # its validation loss has stopped falling

    camera: Literal["front", "chase"] = "front"
    image_size: int = field(default=128, metadata=DERIVED)
    frames: int = 2
    pool: int = 2
    channels: list[int] = field(default_factory=lambda: [16, 32, 32, 32])
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    seen_names: list[str] = field(default_factory=list, metadata=DERIVED)
    seen_index: list[int] = field(default_factory=list, metadata=DERIVED)
    target_names: list[str] = field(default_factory=list, metadata=DERIVED)
    target_index: list[int] = field(default_factory=list, metadata=DERIVED)
    error_names: list[str] = field(default_factory=list, metadata=DERIVED)
    error_index: list[int] = field(default_factory=list, metadata=DERIVED)
    error_seen: list[int] = field(default_factory=list, metadata=DERIVED)
    error_target: list[int] = field(default_factory=list, metadata=DERIVED)
    integral_names: list[str] = field(default_factory=list, metadata=DERIVED)
    integral_index: list[int] = field(default_factory=list, metadata=DERIVED)
    integral_error: list[int] = field(default_factory=list, metadata=DERIVED)
    integral_limit: list[float] = field(default_factory=list, metadata=DERIVED)
    given_names: list[str] = field(default_factory=list, metadata=DERIVED)
    given_index: list[int] = field(default_factory=list, metadata=DERIVED)
    aux_weight: float = 1.0
    roll_augment_deg: float = 15.0
    augment_share: float = 0.5
    noise_scale: float = 1.0
    dt: float = field(default=0.1, metadata=DERIVED)

    def problems(self) -> list[str]:
        problems = []
        if not 1 <= self.frames <= 16:  # each is a full camera frame per sample in memory
            problems.append(f"frames={self.frames}: a vision policy sees 1 to 16 camera frames")
        if self.pool < 1:
            problems.append(f"pool={self.pool} must be >= 1")
        side = self.image_size // max(self.pool, 1) // 2 ** len(self.channels)
        if self.image_size % max(self.pool, 1) or side < 1:
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
        if not self.aux_weight > 0 or not self.noise_scale >= 0:
            problems.append(f"aux_weight={self.aux_weight} must be > 0, noise_scale >= 0")
        if not 0 <= self.roll_augment_deg <= 90 or not 0 <= self.augment_share <= 1:
            problems.append(
                f"roll_augment_deg={self.roll_augment_deg} must lie in [0, 90] and "
                f"augment_share={self.augment_share} in [0, 1]"
            )
        return problems

    @property
    def stateful(self) -> bool:
        return True  # in flight: its last frames and the integrals of the errors it estimated

    @property
    def window(self) -> Window:
        return Window(images=tuple(range(1 - self.frames, 1)), camera=self.camera, pool=self.pool)

    def for_data(self, data: DatasetInfo) -> VisionConfig:
        """This configuration for the dataset's observation, camera size and rate."""
        assert data.image_size is not None, "the window names a camera"
        high = observation_high(data.flight)
        derived = derived_for(list(data.observation_names), high)
        return replace(self, image_size=data.image_size, dt=1.0 / data.fps, **derived)

    @classmethod
    def for_observation(
        cls, names: list[str], high: list[float] | None = None, **kwargs: Any
    ) -> VisionConfig:
        """The config for a task observing ``names`` (``high``: the task's observation
        bounds, ``Task.observation_bounds``, where its integrals saturate): what the eye
        estimates, which errors and integrals the hands recompute from it, and what they
        are given (``derived_for``); ``kwargs`` are the other settings."""
        return cls(**derived_for(names, high), **kwargs)


def derived_for(names: list[str], high: list[float] | None) -> dict[str, Any]:
    """The ``*_names`` and ``*_index`` settings of a vision policy for a task observing
    ``names`` (``VisionConfig.for_observation``)."""
    seen = seen_for(names)
    if not seen:
        raise ConfigError(
            f"the task observes {names}, none of it the aircraft's own state: a vision "
            "policy's camera would show it nothing to estimate; train a state policy"
        )
    targets = [n for n in names if n.endswith("_target")]
    errors = [
        n
        for n in names
        if n.endswith("_error")
        and n.removesuffix("_error") in seen
        and n.removesuffix("_error") + "_target" in targets
    ]
    integrals = [
        n for n in names if n.endswith("_integral") and n.removesuffix("_integral") in errors
    ]
    derived = set(seen) | set(targets) | set(errors) | set(integrals)
    given = [n for n in names if n not in derived]
    variables = [e.removesuffix("_error") for e in errors]
    limits = [float(high[names.index(n)]) if high is not None else 0.0 for n in integrals]
    return {
        "seen_names": seen,
        "seen_index": [names.index(n) for n in seen],
        "target_names": targets,
        "target_index": [names.index(n) for n in targets],
        "error_names": errors,
        "error_index": [names.index(n) for n in errors],
        "error_seen": [seen.index(v) for v in variables],
        "error_target": [targets.index(v + "_target") for v in variables],
        "integral_names": integrals,
        "integral_index": [names.index(n) for n in integrals],
        "integral_error": [errors.index(n.removesuffix("_integral")) for n in integrals],
        "integral_limit": limits,
        "given_names": given,
        "given_index": [names.index(n) for n in given],
    }


def observation_high(flight: FlightSpec | None) -> list[float] | None:
    """The upper observation bounds of ``flight``'s task (where its integrals saturate), or
    None for a dataset without a flight spec."""
    if flight is None:
        return None
    try:
        task = flight.solo_aircraft.task_factory()()
    except ConfigError:  # a spec of several aircraft: the policy saturates nothing
        return None
    return [float(v) for v in task.observation_bounds()[1]]
