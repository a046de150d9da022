"""Rollouts on worker processes: seeded evaluation episodes on 2 workers against 1, measured
against what two processes of pure Python get over one on this machine in the same rounds
(``rollout_workers_vs_ceiling``), and Ray tasks on a local 2-CPU cluster against the 2-worker
process pool (``ray_vs_pool_2_workers``)."""

from __future__ import annotations

import multiprocessing as mp
import time

from benchmarks.common import Row


def _burn(n: int) -> int:
    x = 0
    for i in range(n):
        x += i * i
    return x


def _burn_pair_ratio() -> float:
    """One round of the ceiling: two pure-Python jobs in one process over two processes."""
    n = 3_000_000
    t0 = time.perf_counter()
    _burn(n)
    _burn(n)
    one = time.perf_counter() - t0
    with mp.get_context("fork").Pool(2) as pool:
        t0 = time.perf_counter()
        pool.map(_burn, [n, n])
        two = time.perf_counter() - t0
    return one / two


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
    shares = []  # per round: the kept pool's speed-up over the ceiling measured beside it
    for _ in range(rounds):
        ceiling = _burn_pair_ratio()
        times = {}
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
                times[side] = time.perf_counter() - t0
                best[side] = min(best[side], times[side])
        t0 = time.perf_counter()
        fly_many(flight, agent, seeds, 1)
        shares.append((time.perf_counter() - t0) / times["kept"] / ceiling)
    for side in ("kept", "new"):
        pairs = zip(results["one"], results[side], strict=True)
        assert all((a.rewards == b.rewards).all() for a, b in pairs), "workers changed results"
    ratio = best["one"] / best["kept"]
    shares.sort()
    return Row(
        "rollout_workers_vs_ceiling",
        shares[len(shares) // 2],
        "ratio",
        0.95,
        detail=[
            f"2 workers (kept) over 1: {ratio:.2f}x (best rounds)",
            f"rollouts, 1 worker             {best['one']:7.2f} s",
            f"rollouts, 2 workers, new pool  {best['new']:7.2f} s "
            f"({best['one'] / best['new']:.2f}x)",
            f"rollouts, 2 workers, kept      {best['kept']:7.2f} s",
            "each round's speed-up over the pure-Python 2-process ceiling beside it: "
            + ", ".join(f"{x:.2f}" for x in shares),
        ],
        extra={"new_pool_ratio": best["one"] / best["new"]},
    )


def ray_vs_pool(episodes: int, rounds: int) -> Row:
    """The same evaluation episodes on Ray (a local cluster of this machine's CPUs, tasks on
    warm workers) and on the kept 2-worker process pool, in alternating rounds: pool time
    over Ray time, the median of the rounds."""
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.rollout import AgentSpec, fly_many
    from gymfg_il.workers import Workers

    flight, agent, seeds = FlightSpec.solo(), AgentSpec.controller(), range(episodes)
    ratios, detail = [], []
    with Workers(2) as pool, Workers(2, ray="local") as ray:
        fly_many(flight, agent, range(1000, 1002), pool)  # warm: both keep their envs
        fly_many(flight, agent, range(1000, 1002), ray)
        for _ in range(rounds):
            t0 = time.perf_counter()
            by_pool = fly_many(flight, agent, seeds, pool)
            pool_s = time.perf_counter() - t0
            t0 = time.perf_counter()
            by_ray = fly_many(flight, agent, seeds, ray)
            ray_s = time.perf_counter() - t0
            pairs = zip(by_pool, by_ray, strict=True)
            assert all((a.rewards == b.rewards).all() for a, b in pairs), "Ray changed results"
            ratios.append(pool_s / ray_s)
            detail.append(f"pool {pool_s:6.2f} s, Ray {ray_s:6.2f} s")
    ratios.sort()
    return Row("ray_vs_pool_2_workers", ratios[len(ratios) // 2], "ratio", 0.90, detail=detail)


def rows(quick: bool) -> list[Row]:
    found = [rollout_workers(6 if quick else 16, 2 if quick else 4)]
    try:
        import ray  # noqa: F401
    except ImportError:
        return found
    return [*found, ray_vs_pool(6 if quick else 16, 2 if quick else 4)]
