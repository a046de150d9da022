"""Configuration of the recurrent (GRU) policy: it carries a memory across steps, so it can
infer what one observation does not show (integrator states, trims, a target's motion)."""

from __future__ import annotations

from dataclasses import dataclass

from gymfg_il.policies.configuration import PolicyConfig
from gymfg_il.policies.factory import register_policy
from gymfg_il.policies.window import Window


@register_policy("gru", "gymfg_il.policies.modeling_gru:GRUPolicy")
@dataclass
class GRUConfig(PolicyConfig):
    """Recurrent, trained on windows of sequence_length steps (every frame starts one, so an
    epoch runs over about sequence_length times the steps of an MLP's).

    A GRU over the normalised observations carries a memory from step to step; in flight the
    state runs on for the whole episode.

    Attributes:
        hidden: width of the input layer and of the GRU's state (given a list, the first).
        layers: stacked GRU layers.
        sequence_length: training window in steps; in flight the state runs on.
    """

    hidden: int = 256
    layers: int = 1
    sequence_length: int = 32

    def problems(self) -> list[str]:
        problems = []
        if self.hidden < 1 or self.layers < 1:
            problems.append(f"hidden={self.hidden} and layers={self.layers} must be >= 1")
        if self.sequence_length < 2:
            problems.append(f"sequence_length={self.sequence_length} must be >= 2")
        return problems

    @property
    def stateful(self) -> bool:
        return True

    @property
    def window(self) -> Window:
        steps = tuple(range(self.sequence_length))
        return Window(observation=steps, action=steps, pad=False)
