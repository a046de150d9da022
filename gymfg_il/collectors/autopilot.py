"""Autopilot demonstrations: the task's controller flies seeded episodes (optionally with DART
noise on what it executes; the dataset keeps its clean actions as labels)."""

from __future__ import annotations

from collections.abc import Callable

from gymfg_il.collectors.config import CollectConfig
from gymfg_il.collectors.session import DATASET, LOGS, SessionResult, record_session
from gymfg_il.datasets.from_logs import BuildReport, build_from_logs
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.workers import Workers


def record_autopilot(
    cfg: CollectConfig,
    workers: int | Workers = 1,
    progress: Callable[[int, float], None] | None = None,
) -> SessionResult:
    """Fly ``cfg.episodes`` controller episodes and log them (the dataset is built after)."""
    seeds = range(cfg.seed, cfg.seed + cfg.episodes)
    return record_session(
        cfg.flight(),
        AgentSpec.controller(),
        None,
        seeds,
        cfg.out,
        "autopilot",
        noise=cfg.noise,
        workers=workers,
        progress=progress,
    )


def collect_autopilot(
    cfg: CollectConfig,
    workers: int = 1,
    progress: Callable[[int], Callable[[int, float], None]] | None = None,
) -> tuple[SessionResult, BuildReport]:
    """Record ``cfg``'s episodes on ``workers`` processes, then bring ``cfg.out/dataset`` up
    to date with every log of the session folder.

    ``progress(total)`` is called once the workers run (a bar made before would start a
    thread, and the workers could then not be forked) and returns the per-episode callback."""
    with Workers(min(workers, cfg.episodes)) as pool:
        tick = progress(cfg.episodes) if progress else None
        result = record_autopilot(cfg, workers=pool, progress=tick)
    report = build_from_logs(sorted((cfg.out / LOGS).glob("*.mcap")), cfg.out / DATASET)
    return result, report
