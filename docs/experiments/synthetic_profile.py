"""Where a synthetic pilot's frame goes: the session loop's stages timed as they run.

    PYTHONPATH=. python docs/experiments/synthetic_profile.py [--seconds 60] [--episodes 2]

The display-bound synthetic pilot collects headless through the real session loop
(``cockpit.session.ManualSession``, 30 Hz, altitude, c172p), as ``benchmarks.manual``'s
``synthetic_pilot_x_realtime`` row runs it. Each stage's calls are timed (what the pilot reads
and decides through the ManualController's devices, the phases, the env's step and the
controller, the MCAP log, the display model the pilot reads next) and so is the session's end
(the dataset built from the log). Prints µs a frame for each and the x-realtime each share
allows. The table is in docs/results/speed.md.
"""

from __future__ import annotations

import argparse
import functools
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--seconds", type=float, default=60.0, help="each episode's length")
    p.add_argument("--episodes", type=int, default=2)
    args = p.parse_args(argv)
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    spent: dict[str, float] = {}

    def timed(owner: Any, name: str, label: str) -> None:
        inner: Callable[..., Any] = getattr(owner, name)

        @functools.wraps(inner)
        def wrapper(*a: Any, **k: Any) -> Any:
            t0 = time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                spent[label] = spent.get(label, 0.0) + time.perf_counter() - t0

        setattr(owner, name, wrapper)

    with tempfile.TemporaryDirectory() as tmp:
        cfg = ManualConfig(
            episode_time_s=args.seconds,
            agent_hz=30,
            pilot="synthetic",
            episodes=args.episodes,
            out=Path(tmp),
        )
        session = ManualSession(cfg)
        s = session.stages
        timed(s.input, "poll", "the pilot reads and decides; the devices read")
        timed(s.phases, "apply", "phases")
        timed(s.env, "step", "env.step")
        timed(s.rollout, "step", "the rollout step (env.step and the rest)")
        timed(s.log, "log", "the MCAP log")
        timed(session, "_look", "the display model")
        started = time.perf_counter()
        stats = session.run()
        wall = time.perf_counter() - started
    frames, flown = stats.frames, args.episodes * args.seconds
    loop = wall - stats.closing_s
    spent["the rollout step (env.step and the rest)"] -= spent["env.step"]
    spent["the rest of the loop"] = loop - sum(spent.values())
    print(f"{frames} frames ({flown:.0f} s flown) in {wall:.2f} s: {flown / wall:.1f}x realtime")
    print(f"{'part':<50} {'µs a frame':>10} {'alone: x realtime':>18}")
    for label, seconds in spent.items():
        each = seconds / frames * 1e6
        print(f"{label:<50} {each:10.1f} {1e6 / 30 / each:18.0f}")
    print(f"{'the loop, all of it':<50} {loop / frames * 1e6:10.1f} {flown / loop:18.0f}")
    print(f"the session's end (the dataset built): {stats.closing_s:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
