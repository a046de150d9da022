"""What every policy configuration declares (LeRobot's ``PreTrainedConfig`` in small): its
settings, the data window it learns from, and how it completes itself from the dataset it
trains on. A policy type is a ``PolicyConfig`` subclass and a modeling class, registered by
name (``policies.factory.register_policy``)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import TYPE_CHECKING, Any, ClassVar, Self

from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.policies.window import Window
from gymfg_il.typecheck import type_problems

if TYPE_CHECKING:
    from gymfg_il.envs.flight import FlightSpec


@dataclass(frozen=True)
class DatasetInfo:
    """What a configuration may need to know of the dataset it trains on.

    Attributes:
        observation_names: the names of ``observation.state``'s entries.
        fps: the dataset's rate (agent steps per second).
        flight: the solo flight every episode was flown as, or None where they differ or
            the dataset predates flight specs.
        image_size: side of the camera frames of the policy's ``Window``, or None.
    """

    observation_names: list[str]
    fps: int
    flight: FlightSpec | None = None
    image_size: int | None = None


@dataclass
class PolicyConfig:
    """A policy's settings. Subclasses are dataclasses whose fields are the policy's settings:
    saved in its checkpoint's config.json and given to ``train bc`` as ``--<field>`` flags,
    their help taken from the ``Attributes:`` section (a field with metadata
    ``{"cli": False}`` is filled in from the dataset, ``for_data``, not given). Subclasses
    check their values in ``problems``."""

    type: ClassVar[str] = ""  # the registered name (``register_policy`` sets it)
    # CPU threads torch trains with on cpu unless ``--threads`` says (0: torch decides)
    default_threads: ClassVar[int] = 1
    # a cap on the default epochs (``learning.config.epochs_for``); None: no cap
    max_default_epochs: ClassVar[int | None] = None
    # the type ``train bc`` (and DAgger) trains a policy of this type as, where it is not
    # itself (a PPO policy retrains as the MLP it is); None: this type, trained by ``train bc``
    retrains_as: ClassVar[str | None] = None

    def __post_init__(self) -> None:
        problems = type_problems(self) or self.problems()
        if problems:
            raise ConfigError(join_problems(f"{self.type or type(self).__name__} policy", problems))

    def problems(self) -> list[str]:
        """What is wrong with the settings (each naming the value and the rule), or []."""
        return []

    @property
    def window(self) -> Window:
        """The frames each training sample holds (default: frame ``t`` alone)."""
        return Window()

    @property
    def stateful(self) -> bool:
        """Whether the policy carries state from step to step of an episode (a recurrent
        state, integrals of errors): every consumer resets it at an episode's start
        (``PolicyAgent.reset``) and calls the policy at every step, also where its action is
        not flown (a person's takeover), so the state follows the flight. Default: none."""
        return False

    def for_data(self, data: DatasetInfo) -> Self:
        """This configuration completed from the dataset it trains on (default: as it is)."""
        return self

    def to_dict(self) -> dict[str, Any]:
        """What config.json keeps under ``policy``: the type and every setting."""
        return {"type": self.type, **asdict(self)}

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> Self:
        """The configuration a checkpoint's ``policy`` entry describes (``type`` is skipped)."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(k for k in values if k not in known and k != "type")
        if unknown:
            raise ConfigError(
                f"{cls.type} policy: no setting {', '.join(unknown)} (settings: "
                f"{', '.join(sorted(known))}); the checkpoint was written by another version"
            )
        return cls(**{k: v for k, v in values.items() if k != "type"})
