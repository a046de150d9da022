"""Configuration of the MLP policy: observation -> action, one step at a time."""

from __future__ import annotations

from dataclasses import dataclass, field

from gymfg_il.policies.configuration import PolicyConfig
from gymfg_il.policies.factory import register_policy


@register_policy("mlp", "gymfg_il.policies.modeling_mlp:MLPPolicy")
@dataclass
class MLPConfig(PolicyConfig):
    """One observation in, one action out: a feed-forward network on the normalised
    observation.

    Attributes:
        hidden: widths of the hidden layers.
        dropout: dropout after each hidden layer (0 = none).
    """

    hidden: list[int] = field(default_factory=lambda: [256, 256])
    dropout: float = 0.0

    def problems(self) -> list[str]:
        problems = []
        if not self.hidden or min(self.hidden) < 1:
            problems.append(f"hidden={self.hidden!r} must be a non-empty list of widths > 0")
        if not 0.0 <= self.dropout < 1.0:
            problems.append(f"dropout={self.dropout!r} must lie in [0, 1)")
        return problems
