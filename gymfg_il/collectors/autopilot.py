"""Autopilot demonstrations: the task's controller flies seeded episodes (optionally with DART
noise on what it executes; the dataset keeps its clean actions as labels)."""

from __future__ import annotations

import logging
from collections.abc import Callable

from gymfg_il.collectors.config import CollectConfig
from gymfg_il.collectors.session import (
    DATASET,
    LOGS,
    SessionResult,
    collected,
    record_session,
)
from gymfg_il.datasets.from_logs import BuildReport, build_from_logs
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.workers import Workers

log = logging.getLogger(__name__)


def seeds_to_fly(cfg: CollectConfig) -> list[int]:
    """``cfg``'s seeds less those whose episode the session's dataset already holds (the
    same flight, source and noise): running a recipe twice re-makes its dataset instead of
    doubling it."""
    noise = cfg.dart_noise()
    held = collected(cfg.out, cfg.flight(), "autopilot")
    have = {seed for seed, n in held if n == noise}
    seeds = [s for s in range(cfg.seed, cfg.seed + cfg.episodes) if s not in have]
    other = sorted({n for seed, n in held if seed in seeds and n != noise})
    if other:  # e.g. a dataset made before its task's own noise changed
        log.warning(
            "the dataset at %s holds episodes of these seeds flown with noise %s; these fly "
            "with %g (%s) and join them: pass --noise %g to re-make those instead",
            cfg.out / DATASET,
            ", ".join(f"{n:g}" for n in other),
            noise,
            "as asked" if cfg.noise is not None else "the task's own",
            other[0],
        )
    if len(seeds) < cfg.episodes:
        log.info(
            "the dataset at %s already holds %d of these episodes; flying the other %d",
            cfg.out / DATASET,
            cfg.episodes - len(seeds),
            len(seeds),
        )
    return seeds


def record_autopilot(
    cfg: CollectConfig,
    workers: int | Workers = 1,
    progress: Callable[[int, float], None] | None = None,
    seeds: list[int] | None = None,
) -> SessionResult:
    """Fly ``cfg``'s controller episodes (``seeds``: these of them) and log them (the
    dataset is built after)."""
    return record_session(
        cfg.flight(),
        AgentSpec.controller(),
        None,
        range(cfg.seed, cfg.seed + cfg.episodes) if seeds is None else seeds,
        cfg.out,
        "autopilot",
        noise=cfg.dart_noise(),
        workers=workers,
        progress=progress,
        images=cfg.images,
        image_size=cfg.image_size,
    )


def collect_autopilot(
    cfg: CollectConfig,
    workers: int = 1,
    progress: Callable[[int], Callable[[int, float], None]] | None = None,
    ray: str | None = None,
) -> tuple[SessionResult, BuildReport | None]:
    """Record ``cfg``'s episodes (those the dataset lacks, ``seeds_to_fly``) on ``workers``
    processes (or on the Ray cluster at ``ray``: ``workers.Workers``), then bring
    ``cfg.out/dataset`` up to date with every log of the session.

    ``progress(total)`` is called once the workers run (a bar made before would start a
    thread, and the workers could then not be forked) and returns the per-episode callback."""
    seeds = seeds_to_fly(cfg)
    with Workers(max(1, min(workers, len(seeds))), ray=ray if seeds else None) as pool:
        tick = progress(len(seeds)) if progress and seeds else None
        result = record_autopilot(cfg, workers=pool, progress=tick, seeds=seeds)
    logs = sorted((cfg.out / LOGS).glob("*.mcap"))
    if not logs:  # nothing flown, and the dataset came without its logs (a bundled one)
        return result, None
    return result, build_from_logs(logs, cfg.out / DATASET)
