"""Autopilot demonstrations: the task's controller flies seeded episodes (optionally with DART
noise on what it executes; the dataset keeps its clean actions as labels)."""

from __future__ import annotations

from collections.abc import Callable

from gymfg_il.collectors.config import CollectConfig
from gymfg_il.collectors.session import DATASET, LOGS, SessionResult, record_session
from gymfg_il.parallel import AgentSpec, EnvSpec, Workers

__all__ = ["DATASET", "LOGS", "env_spec", "record_autopilot"]


def env_spec(cfg: CollectConfig) -> EnvSpec:
    return EnvSpec(
        cfg.task, cfg.aircraft, cfg.dynamic, cfg.agent_hz, cfg.episode_time_s, dict(cfg.task_kwargs)
    )


def record_autopilot(
    cfg: CollectConfig,
    workers: int | Workers = 1,
    progress: Callable[[int, float], None] | None = None,
) -> SessionResult:
    """Fly ``cfg.episodes`` controller episodes and log them (the dataset is built after)."""
    seeds = range(cfg.seed, cfg.seed + cfg.episodes)
    return record_session(
        env_spec(cfg),
        AgentSpec.controller(),
        None,
        seeds,
        cfg.out,
        "autopilot",
        noise=cfg.noise,
        workers=workers,
        progress=progress,
    )
