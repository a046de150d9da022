"""A process pool for seeded work, with results identical to one worker.

Every episode depends only on its seed (the env is reset with it, the agent too), so seeds can
be dealt to workers in any way; results come back in seed order. Workers build what they fly
from picklable specs (``FlightSpec``, ``AgentSpec``) and keep it between episodes (``kept``).

``map_seeds(..., workers=2)`` starts a pool for the call; ``with Workers(2) as workers:``
keeps one for several calls (evaluating several agents, rounds of episodes).

``Workers(n, ray=ADDRESS)`` runs the episodes as Ray tasks instead, on every node of a Ray
cluster (``auto``: the cluster this machine belongs to, ``local``: one started in-process, or
``HOST:PORT``). Ray reuses its worker processes, so the kept env stays warm there too; a task
whose worker or node dies is run again elsewhere (``RAY_RETRIES``), and results still come
back in seed order to this process, which writes every log and dataset.
"""

from __future__ import annotations

import multiprocessing as mp
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

from gymfg_il.errors import ConfigError, EnvStateError

T = TypeVar("T")


# What this process flies with, kept between episodes (in a worker, between calls too):
# key -> (env, agents...), one set at a time.
_kept: dict[str, tuple[Any, ...]] = {}


def kept[K: tuple[Any, ...]](key: str, build: Callable[[], K]) -> K:
    """The env and agents known by ``key``, built on first use. One set is kept at a time:
    a kept pool that moves on to another agent (eval's next one, DAgger's next round)
    closes the last set instead of piling them up."""
    if key not in _kept:
        release_kept()
        _kept[key] = build()
    return _kept[key]  # type: ignore[return-value]  # stored by the build for this key


def release_kept() -> None:
    """Close the kept env (the end of a call in this process)."""
    for env, *_ in _kept.values():
        env.close()
    _kept.clear()


def _count(workers: object) -> int:
    if not (isinstance(workers, int) and not isinstance(workers, bool) and workers >= 1):
        raise ConfigError(f"workers={workers!r}: give 1 or more worker processes")
    return workers


def _worker_init() -> None:
    """One core per worker: two workers whose torch each spins two OpenMP threads on a
    2-core machine ran policy episodes 20x slower."""
    import os
    import sys

    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[var] = "1"  # read when torch is first imported in this worker
    if "torch" in sys.modules:  # imported already (a forked worker)
        sys.modules["torch"].set_num_threads(1)


def _start_method() -> str:
    """fork when it is safe (workers then start in milliseconds with everything imported);
    forkserver when this process runs other threads (forking them can deadlock); spawn where
    neither exists."""
    methods = mp.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return "fork"
    if "forkserver" in methods:
        mp.set_forkserver_preload(["gymfg_il.workers", "gymfg_il.rollout.seeded"])
        return "forkserver"
    return "spawn"


def _call[T](job: tuple[Callable[..., T], tuple[Any, ...]]) -> T:
    fn, args = job
    return fn(*args)


RAY_RETRIES = 3  # runs of an episode whose worker or node died, before the run fails


def _seed_task[T](fn: Callable[..., T], args: tuple[Any, ...], seed: int) -> T:
    return fn(*args, seed)


def _refused_token(err: BaseException | None) -> bool:
    """Whether Ray's connection error came from token authentication (Ray wraps its
    AuthenticationError in a RuntimeError's text, in a ConnectionError)."""
    while err is not None:
        if "InvalidAuthToken" in str(err) or type(err).__name__ == "AuthenticationError":
            return True
        err = err.__cause__ or err.__context__
    return False


class _RayTasks:
    """Episodes as Ray tasks: connected at start, disconnected (a local cluster stopped) at
    close."""

    def __init__(self, address: str) -> None:
        import os
        from pathlib import Path

        # Ray 2.60's `ray start --head` turns on token authentication when a token is at hand
        # (~/.ray/auth_token, or RAY_AUTH_TOKEN / RAY_AUTH_TOKEN_PATH); a driver must say it
        # uses it before Ray is imported
        token = any(os.environ.get(v) for v in ("RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH"))
        if address != "local" and (token or (Path.home() / ".ray" / "auth_token").is_file()):
            os.environ.setdefault("RAY_AUTH_MODE", "token")
        # Ray starts its workers at nice 15: beside any other work (a training run, a build)
        # they got what was left and flew episodes 8-10x slower than the process pool. A
        # cluster started here runs them at normal priority (`ray start` takes the same
        # RAY_worker_niceness=0).
        os.environ.setdefault("RAY_worker_niceness", "0")
        try:
            import ray
        except ImportError:
            raise ConfigError(
                f"--ray {address}: Ray is not installed; pip install -e '.[ray]'"
            ) from None
        self.ray = ray
        self.started = not ray.is_initialized()
        if self.started:
            try:
                if address == "local":
                    ray.init(include_dashboard=False, log_to_driver=False)
                else:
                    ray.init(address=address, log_to_driver=False)
            except (ConnectionError, ValueError, RuntimeError) as err:
                if _refused_token(err):
                    raise ConfigError(
                        f"--ray {address}: the cluster refused this process's token; give it "
                        "the cluster's (RAY_AUTH_TOKEN_PATH=FILE, or ~/.ray/auth_token as on "
                        "its head) with RAY_AUTH_MODE=token"
                    ) from None
                first = str(err).strip().splitlines()[0] if str(err).strip() else ""
                raise ConfigError(
                    f"--ray {address}: no Ray cluster there ({first}); start one with `ray "
                    "start --head`, or give --ray local to start one in this process"
                ) from None
        self.task: Any = ray.remote(num_cpus=1, max_retries=RAY_RETRIES)(_seed_task)
        self.slots = max(1, int(ray.cluster_resources().get("CPU", 1)))

    def imap[T](self, fn: Callable[..., T], args: tuple[Any, ...], seeds: list[int]) -> Iterator[T]:
        """``fn(*args, seed)`` per seed, in seed order; a few tasks per CPU in flight, so a
        long run holds no more than that in the cluster's object store."""
        from collections import deque

        ray = self.ray
        shared = ray.put(args)
        todo = iter(seeds)
        flying: deque[Any] = deque()
        for seed in todo:
            flying.append(self.task.remote(fn, shared, seed))
            if len(flying) >= 4 * self.slots:
                break
        while flying:
            result = ray.get(flying.popleft())
            following = next(todo, None)
            if following is not None:
                flying.append(self.task.remote(fn, shared, following))
            yield result

    def close(self) -> None:
        if self.started and self.ray.is_initialized():
            self.ray.shutdown()


class Workers:
    """Worker processes kept for several ``map_seeds`` calls; ``close()`` (or the end of a
    ``with`` block) stops them.

    A new worker costs more than its start: it touches memory it shares with its parent,
    each page then copied for it, and a start by ``forkserver`` (the safe choice once this
    process runs threads) re-imports everything. Work that comes in several calls (eval's
    agents, DAgger's rounds) therefore shares one pool, started here, before the caller
    starts threads (a progress bar's monitor, training). ``Workers(1)`` starts no process:
    its work runs in this one.
    """

    def __init__(self, n: int, ray: str | None = None) -> None:
        self.n = _count(n)
        self.closed = False
        self._ray = _RayTasks(ray) if ray else None
        if self._ray is not None:
            self.n = max(2, self._ray.slots)  # the cluster's CPUs, never this process alone
        ctx = mp.get_context(_start_method())
        self._pool: Any = ctx.Pool(n, initializer=_worker_init) if n > 1 and not ray else None

    def _imap[T](
        self, fn: Callable[..., T], args: tuple[Any, ...], seeds: list[int]
    ) -> Iterator[T]:
        if self._ray is not None:
            yield from self._ray.imap(fn, args, seeds)
            return
        jobs = [(fn, (*args, seed)) for seed in seeds]
        # one episode per task: a task costs ~0.1 ms to send, an episode ~100 ms to fly, and
        # the last worker to finish then waits at most one episode
        results = self._pool.imap(_call, jobs, chunksize=1)
        for _ in jobs:
            if self.closed:  # a terminated pool's iterator would wait forever
                raise EnvStateError("these Workers were closed while their results were read")
            yield next(results)

    def close(self) -> None:
        self.closed = True
        if self._ray is not None:
            self._ray.close()
            self._ray = None
        if self._pool is not None:
            self._pool.terminate()
            self._pool.join()
            self._pool = None

    def __enter__(self) -> Workers:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def map_seeds[T](
    fn: Callable[..., T],
    args: tuple[Any, ...],
    seeds: Sequence[int],
    workers: int | Workers = 1,
) -> Iterator[T]:
    """``fn(*args, seed)`` for every seed, yielded in seed order, on ``workers`` processes
    (a number: a pool for this call; ``Workers``: that pool, left running).

    ``fn`` must be a module-level function (it is pickled by name)."""
    seeds = list(seeds)
    if isinstance(workers, Workers):
        if workers.closed:
            raise EnvStateError("these Workers are closed; start new ones")
        n = workers.n
    else:
        n = _count(workers)
    if n == 1 or len(seeds) <= 1:
        for seed in seeds:
            yield fn(*args, seed)
        return
    if isinstance(workers, Workers):
        yield from workers._imap(fn, args, seeds)
        return
    with Workers(min(n, len(seeds))) as pool:
        yield from pool._imap(fn, args, seeds)
