"""Evaluation episodes on worker processes (see ``gymfg_il.parallel``)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from gymfg_il.evaluation.rollout import Episode, fly_episode
from gymfg_il.parallel import AgentSpec, EnvSpec, Workers, map_seeds

_cache: dict[str, tuple[Any, Any]] = {}


def _fly(env_spec: EnvSpec, agent_spec: AgentSpec, seed: int) -> Episode:
    # Workers keep their env and agent between seeds (each episode is reset by its seed),
    # one pair at a time: a kept pool that moves on to another agent closes the last one.
    key = repr((env_spec, agent_spec.key()))
    if key not in _cache:
        _close_cached()
        env = env_spec.make()
        _cache[key] = (env, agent_spec.make(env))
    env, agent = _cache[key]
    return fly_episode(env, agent, seed)


def fly_many(
    env_spec: EnvSpec,
    agent_spec: AgentSpec,
    seeds: Sequence[int],
    workers: int | Workers = 1,
    progress: Callable[[], None] | None = None,
) -> list[Episode]:
    """One episode per seed, in seed order, on ``workers`` processes."""
    out = []
    try:
        for episode in map_seeds(_fly, (env_spec, agent_spec), seeds, workers):
            out.append(episode)
            if progress:
                progress()
    finally:
        _close_cached()
    return out


def _close_cached() -> None:
    for env, _ in _cache.values():
        env.close()
    _cache.clear()


__all__ = ["AgentSpec", "EnvSpec", "Workers", "fly_many"]
