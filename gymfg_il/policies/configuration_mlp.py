"""Configuration of the MLP policy: observation -> action, one step at a time."""

from __future__ import annotations

from dataclasses import dataclass, field

from gymfg_il.errors import ConfigError


@dataclass
class MLPConfig:
    """A feed-forward policy on the normalised observation.

    Attributes:
        hidden: widths of the hidden layers.
        dropout: dropout after each hidden layer (0 = none).
    """

    type: str = "mlp"
    hidden: list[int] = field(default_factory=lambda: [256, 256])
    dropout: float = 0.0

    def __post_init__(self) -> None:
        if not self.hidden or not all(isinstance(h, int) and h > 0 for h in self.hidden):
            raise ConfigError(f"hidden={self.hidden!r} must be a non-empty list of widths > 0")
        if not 0.0 <= self.dropout < 1.0:
            raise ConfigError(f"dropout={self.dropout!r} must lie in [0, 1)")
