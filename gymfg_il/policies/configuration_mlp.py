"""Configuration of the MLP policy: observation -> action, one step at a time, optionally with
the integrals of its task's expert loops as a memory (``policies.memory``)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

from gymfg_il.errors import ConfigError
from gymfg_il.policies.configuration import DatasetInfo, PolicyConfig
from gymfg_il.policies.factory import register_policy

DERIVED = {"cli": False}  # filled in from the dataset (``for_data``), not given


@register_policy("mlp", "gymfg_il.policies.modeling_mlp:MLPPolicy")
@dataclass
class MLPConfig(PolicyConfig):
    """One observation in, one action out: a feed-forward network on the normalised
    observation.

    Attributes:
        hidden: widths of the hidden layers.
        dropout: dropout after each hidden layer (0 = none).
        memory: `loops`: the policy also sees the integrals of the errors its task's expert
            loops track (climb rate, pitch, roll, airspeed, slip), run on its own
            observations from the episode's start, so it can hold what a demonstrator
            integrates (trim, PID integrals); `none`: the observation alone.
    """

    hidden: list[int] = field(default_factory=lambda: [256, 256])
    dropout: float = 0.0
    memory: Literal["none", "vertical", "loops"] = "none"
    memory_flight: dict[str, Any] | None = field(default=None, metadata=DERIVED)
    memory_observation: list[str] = field(default_factory=list, metadata=DERIVED)

    def problems(self) -> list[str]:
        problems = []
        if not self.hidden or min(self.hidden) < 1:
            problems.append(f"hidden={self.hidden!r} must be a non-empty list of widths > 0")
        if not 0.0 <= self.dropout < 1.0:
            problems.append(f"dropout={self.dropout!r} must lie in [0, 1)")
        return problems

    def to_dict(self) -> dict[str, Any]:
        """Without memory, written as before memory existed (older readers load it)."""
        out = super().to_dict()
        if self.memory == "none":
            for name in ("memory", "memory_flight", "memory_observation"):
                out.pop(name)
        return out

    @property
    def stateful(self) -> bool:
        return self.memory != "none"

    def for_data(self, data: DatasetInfo) -> MLPConfig:
        """With ``memory``, the flight the expert loops are taken from and the observation
        they read (the dataset's, less the memory's own columns)."""
        if self.memory == "none":
            return self
        from gymfg_il.policies.memory import NAMES

        if data.flight is None or not data.flight.is_solo:
            raise ConfigError(
                f"--memory {self.memory} runs the task's expert loops, so it needs a dataset of one "
                "solo flight spec (this one has none, or several); train with --memory none"
            )
        observed = [n for n in data.observation_names if n not in NAMES]
        return replace(self, memory_flight=data.flight.to_dict(), memory_observation=observed)

    @property
    def memory_names(self) -> tuple[str, ...]:
        """The memory's own columns, after the observation's (none without memory)."""
        from gymfg_il.policies.memory import names_of

        return names_of(self.memory)
