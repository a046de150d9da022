"""Rollouts on worker processes: seeded evaluation episodes on 2 workers against 1, beside
what two processes of pure Python get over one on this machine at that moment."""

from __future__ import annotations

import multiprocessing as mp
import time

from benchmarks.common import Row


def _burn(n: int) -> int:
    x = 0
    for i in range(n):
        x += i * i
    return x


def cpu_ceiling(rounds: int) -> float:
    """What two processes of pure Python get over one here now (the ceiling of any 2-worker
    speed-up; on a shared VM it moves from run to run)."""
    n = 3_000_000
    best = 0.0
    for _ in range(rounds):
        t0 = time.perf_counter()
        _burn(n)
        _burn(n)
        one = time.perf_counter() - t0
        with mp.get_context("fork").Pool(2) as pool:
            t0 = time.perf_counter()
            pool.map(_burn, [n, n])
            two = time.perf_counter() - t0
        best = max(best, one / two)
    return best


def rollout_workers(episodes: int, rounds: int) -> Row:
    """Wall time of evaluation episodes (controller, altitude, c172p, 90 s) in this process,
    on 2 workers that have flown another task before (kept, as ``eval`` keeps them for its
    next agent), and on a new 2-worker pool (start and warm-up included); best of alternating
    rounds. Each round's kept pool lives for that round only: its threads, left running,
    would make the new pool start by forkserver instead of fork."""
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.rollout import AgentSpec, fly_many
    from gymfg_il.workers import Workers

    flight, agent, seeds = FlightSpec.solo(), AgentSpec.controller(), range(episodes)
    best = {"one": float("inf"), "kept": float("inf"), "new": float("inf")}
    results = {}
    for _ in range(rounds):
        for side in best:
            if side != "kept":
                t0 = time.perf_counter()
                results[side] = fly_many(flight, agent, seeds, {"one": 1, "new": 2}[side])
                best[side] = min(best[side], time.perf_counter() - t0)
                continue
            with Workers(2) as kept:
                # earlier work, as eval's previous agent: another task, so the timed call
                # still builds its own env and agent in every worker
                fly_many(FlightSpec.solo(task="roll"), agent, range(1000, 1004), kept)
                t0 = time.perf_counter()
                results[side] = fly_many(flight, agent, seeds, kept)
                best[side] = min(best[side], time.perf_counter() - t0)
    for side in ("kept", "new"):
        pairs = zip(results["one"], results[side], strict=True)
        assert all((a.rewards == b.rewards).all() for a, b in pairs), "workers changed results"
    ratio = best["one"] / best["kept"]
    return Row(
        "rollout_workers_2_vs_1",
        ratio,
        "ratio",
        1.8,
        detail=[
            f"rollouts, 1 worker             {best['one']:7.2f} s",
            f"rollouts, 2 workers, new pool  {best['new']:7.2f} s "
            f"({best['one'] / best['new']:.2f}x)",
            f"rollouts, 2 workers, kept      {best['kept']:7.2f} s",
            f"pure-Python 2-process ceiling here now: {cpu_ceiling(3):.2f}x",
        ],
        extra={"new_pool_ratio": best["one"] / best["new"]},
    )


def rows(quick: bool) -> list[Row]:
    return [rollout_workers(6 if quick else 16, 2 if quick else 4)]
