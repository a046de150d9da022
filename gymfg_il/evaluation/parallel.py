"""Evaluation episodes on worker processes (see ``gymfg_il.parallel``)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from gymfg_il.evaluation.rollout import Episode, fly_episode
from gymfg_il.parallel import AgentSpec, EnvSpec, Workers, kept, map_seeds, release_kept


def _fly(env_spec: EnvSpec, agent_spec: AgentSpec, seed: int) -> Episode:
    # the env and agent are kept between seeds (each episode is reset by its seed)
    def build() -> tuple[Any, Any]:
        env = env_spec.make()
        return env, agent_spec.make(env)

    env, agent = kept(repr((env_spec, agent_spec.key())), build)
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
        release_kept()
    return out


__all__ = ["AgentSpec", "EnvSpec", "Workers", "fly_many"]
