"""Configuration of the chunking policy: a short observation history in, the next ``chunk``
actions out, flown with temporal ensembling (ACT, Zhao et al. 2023, without the transformer
and the CVAE: an MLP small enough to train on two cores in minutes)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from gymfg_il.policies.configuration import PolicyConfig
from gymfg_il.policies.factory import register_policy
from gymfg_il.policies.window import Window


@register_policy("chunk", "gymfg_il.policies.modeling_chunk:ChunkPolicy")
@dataclass
class ChunkConfig(PolicyConfig):
    """An observation history in, a chunk of future actions out, flown with temporal
    ensembling, as ACT does.

    Attributes:
        hidden: widths of the hidden layers.
        history: observations the policy sees (the current one and ``history - 1`` before
            it; at an episode's start the first is repeated).
        chunk: actions predicted at every step (the current one and the next ``chunk - 1``).
        ensemble_decay: temporal ensembling: the action flown is the weighted average of every
            live chunk's prediction for this step, a chunk predicted ``age`` steps ago weighted
            ``exp(-ensemble_decay * age)`` (0: equal weights; ACT weights the oldest most, a
            negative decay here).
    """

    hidden: list[int] = field(default_factory=lambda: [256, 256])
    history: int = 4
    chunk: int = 10
    ensemble_decay: float = 0.5

    def problems(self) -> list[str]:
        problems = []
        if not self.hidden or min(self.hidden) < 1:
            problems.append(f"hidden={self.hidden!r} must be a non-empty list of widths > 0")
        if self.history < 1 or self.chunk < 1:
            problems.append(f"history={self.history} and chunk={self.chunk} must be >= 1")
        if not math.isfinite(self.ensemble_decay):
            problems.append(f"ensemble_decay={self.ensemble_decay} must be a number")
        return problems

    @property
    def stateful(self) -> bool:
        return True  # in flight: its last observations and the chunks still being flown

    @property
    def window(self) -> Window:
        return Window(
            observation=tuple(range(1 - self.history, 1)), action=tuple(range(self.chunk))
        )
