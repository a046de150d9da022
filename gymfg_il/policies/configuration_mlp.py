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
        memory: what the policy remembers besides the observation: the integrals of the
            errors its task's expert loops track, run on its own observations from the
            episode's start, so it can hold what a demonstrator integrates (trim, PID
            integrals). `vertical`: the climb-rate and pitch loops (what holds an
            altitude); `loops`: every loop (also roll, airspeed, slip); `none`: the
            observation alone; `auto`: what the task asks for (`Task.memory`):
            `vertical` for altitude, pitch, turn, climb-turn, waypoints and approach
            (`loops` for the heading, the turn, the climb-turn and the approach from their
            autopilot's demonstrations),
            `none` for the tasks that hold their start altitude (roll, heading, airspeed,
            sideslip, level) and formation, or where the dataset is not of one solo flight.
            From the autopilot's demonstrations the memory starts at, and is held near, the
            autopilot's own integral terms.
    """

    hidden: list[int] = field(default_factory=lambda: [256, 256])
    dropout: float = 0.0
    memory: Literal["auto", "none", "vertical", "loops"] = "auto"
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
        """Without memory, no flight or observation of it; ``auto`` (not yet chosen for a
        dataset) written as before memory existed."""
        out = super().to_dict()
        if not self.memory_names:
            out.pop("memory_flight")
            out.pop("memory_observation")
        if self.memory == "auto":
            out.pop("memory")
        return out

    @property
    def stateful(self) -> bool:
        return bool(self.memory_names)

    def for_data(self, data: DatasetInfo) -> MLPConfig:
        """With memory, the kind the data holds (``learning.memory.remembered`` appended its
        columns), the flight its loops are taken from and the observation they read."""
        from gymfg_il.policies.memory import NAMES, kind_of

        kind: Any = kind_of(data.observation_names)  # one of LOOPS' names
        if self.memory not in ("auto", kind):
            raise ConfigError(
                f"--memory {self.memory}: the frames hold the memory {kind!r}; train on "
                "frames that learning.memory.remembered extended for this configuration"
            )
        if kind == "none":
            return replace(self, memory="none")
        assert data.flight is not None, "remembered needs a flight"
        observed = [n for n in data.observation_names if n not in NAMES]
        return replace(
            self, memory=kind, memory_flight=data.flight.to_dict(), memory_observation=observed
        )

    @property
    def memory_names(self) -> tuple[str, ...]:
        """The memory's own columns, after the observation's (none without memory, or
        before ``for_data`` has chosen it)."""
        from gymfg_il.policies.memory import names_of

        return names_of(self.memory) if self.memory != "auto" else ()
