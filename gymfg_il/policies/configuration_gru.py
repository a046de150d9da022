"""Configuration of the recurrent (GRU) policy: it carries a memory across steps, so it can
infer what one observation does not show (integrator states, trims, a target's motion)."""

from __future__ import annotations

from dataclasses import dataclass

from gymfg_il.errors import ConfigError


@dataclass
class GRUConfig:
    """A GRU over the normalised observations, trained on windows of ``sequence_length``.

    Attributes:
        hidden: GRU state width.
        layers: stacked GRU layers.
        sequence_length: training window (steps); at flight time the state runs on.
    """

    type: str = "gru"
    hidden: int = 128
    layers: int = 1
    sequence_length: int = 32

    def __post_init__(self) -> None:
        problems = []
        if self.hidden < 1 or self.layers < 1:
            problems.append("hidden and layers must be >= 1")
        if self.sequence_length < 2:
            problems.append(f"sequence_length={self.sequence_length} must be >= 2")
        if problems:
            raise ConfigError("GRUConfig: " + "; ".join(problems))
