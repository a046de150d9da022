"""Running seeded episodes across worker processes, with results identical to one worker.

Every episode depends only on its seed (the env is reset with it, the agent too), so seeds can
be dealt to workers in any way; results come back in seed order. Workers build their own env
and agents from picklable specs (``EnvSpec``, ``AgentSpec``) and keep them between episodes.

``map_seeds(..., workers=2)`` starts a pool for the call; ``with Workers(2) as workers:``
keeps one for several calls (evaluating several agents, rounds of episodes).
"""

from __future__ import annotations

import multiprocessing as mp
import threading
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError, EnvStateError

T = TypeVar("T")


@dataclass(frozen=True)
class EnvSpec:
    """What builds an ``AircraftEnv``."""

    task: str = "altitude"
    aircraft: str = "c172p"
    dynamic: bool = False
    agent_hz: int = 10
    episode_time_s: float = 90.0
    task_kwargs: dict[str, Any] = field(default_factory=dict)
    views: tuple[int, ...] = ()  # FlightGear UDP ports (real time while attached)

    def make(self) -> AircraftEnv:
        return AircraftEnv(
            self.task,
            self.aircraft,
            dynamic=self.dynamic,
            task_kwargs=self.task_kwargs,
            agent_hz=self.agent_hz,
            episode_time_s=self.episode_time_s,
            views=self.views or None,
        )


@dataclass(frozen=True)
class AgentSpec:
    """What builds an agent for an env: the task's controller or a policy checkpoint."""

    kind: str
    path: Path | None = None

    @classmethod
    def controller(cls) -> AgentSpec:
        return cls("controller")

    @classmethod
    def policy(cls, path: Path) -> AgentSpec:
        return cls("policy", Path(path))

    def key(self) -> str:
        """What a worker's cache knows this agent by: its spec, and for a checkpoint the
        time and size of its config and weights (one retrained in place is loaded afresh)."""
        if self.path is None:
            return repr(self)
        from gymfg_il.policies.factory import CONFIG_FILE, WEIGHTS_FILE

        stamps: list[tuple[int, int] | None] = []
        for name in (CONFIG_FILE, WEIGHTS_FILE):
            try:
                st = (self.path / name).stat()
                stamps.append((st.st_mtime_ns, st.st_size))
            except OSError:
                stamps.append(None)  # loading it will say what is missing
        return repr((self, stamps))

    def meta(self) -> dict[str, Any]:
        from gymfg_il.policies.factory import read_config

        assert self.path is not None
        return read_config(self.path)

    def make(self, env: AircraftEnv) -> Any:
        if self.kind == "controller":
            from gymfg_il.controllers.autopilot import controller_for

            return controller_for(
                env.task, env.aircraft.model, env.dt, env.aircraft.profile.cruise_throttle
            )
        from gymfg_il.policies.agent import PolicyAgent

        assert self.path is not None
        agent = PolicyAgent.load(self.path)
        agent.check_observation(env.observation_names)
        return agent


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
        mp.set_forkserver_preload(
            ["gymfg_il.parallel", "gymfg_il.evaluation.parallel", "gymfg_il.collectors.session"]
        )
        return "forkserver"
    return "spawn"


def _call[T](job: tuple[Callable[..., T], tuple[Any, ...]]) -> T:
    fn, args = job
    return fn(*args)


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

    def __init__(self, n: int) -> None:
        self.n = _count(n)
        self.closed = False
        ctx = mp.get_context(_start_method())
        self._pool: Any = ctx.Pool(n, initializer=_worker_init) if n > 1 else None

    def _imap[T](
        self, fn: Callable[..., T], args: tuple[Any, ...], seeds: list[int]
    ) -> Iterator[T]:
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
