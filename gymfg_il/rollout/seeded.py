"""Seeded episodes of a solo flight, on worker processes that keep their env and agents warm.

``fly_many(flight, pilot, seeds, expert=..., noise=..., workers=...)`` yields one ``Episode``
per seed, in seed order, identical for any number of workers: evaluation, autopilot
collection and DAgger all fly through it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.rollout.records import Episode
from gymfg_il.workers import Workers, kept, map_seeds, release_kept


def fly_seed(
    flight: FlightSpec, pilot: AgentSpec, expert: AgentSpec | None, noise: float, seed: int
) -> Episode:
    """One episode of ``flight`` seeded with ``seed`` (the env and agents are kept between
    calls in this process, and rebuilt when the flight or an agent changes)."""

    def build() -> tuple[Any, Rollout]:
        env = flight.make_env()
        experts = [expert.make(env)] if expert else None
        return env, Rollout(env, [pilot.make(env)], experts=experts, noise=noise)

    key = repr((flight, pilot.key(), expert.key() if expert else None, noise))
    _, rollout = kept(key, build)
    return rollout.episode(seed)


def fly_many(
    flight: FlightSpec,
    pilot: AgentSpec,
    seeds: Sequence[int],
    workers: int | Workers = 1,
    **options: Any,
) -> list[Episode]:
    """One episode per seed, in seed order, on ``workers`` processes (``options``: those of
    ``iter_many``)."""
    return list(iter_many(flight, pilot, seeds, workers, **options))


def iter_many(
    flight: FlightSpec,
    pilot: AgentSpec,
    seeds: Sequence[int],
    workers: int | Workers = 1,
    *,
    expert: AgentSpec | None = None,
    noise: float = 0.0,
    progress: Callable[[Episode], None] | None = None,
) -> Iterator[Episode]:
    """``fly_many`` as the episodes arrive (a recorder writes each before the next comes)."""
    try:
        for episode in map_seeds(fly_seed, (flight, pilot, expert, noise), seeds, workers):
            if progress is not None:
                progress(episode)
            yield episode
    finally:
        release_kept()
