"""Where a ``train ppo`` run's wall time goes: sampling (the env processes stepping, the
policy's actions, the rollout's transfer), the updates, and the evaluations (the curve's and
the kept actor's choice), timed in the trainer's process around stable-baselines3's
``collect_rollouts`` and ``train`` and the run's ``Judge``.

    PYTHONPATH=. python docs/experiments/ppo_wall.py DATASET_OR_POLICY [--steps 200000]

A dataset folder is cloned first (``train bc``, default flags); the run is the altitude in
moderate turbulence with default flags, as docs/results/rl.md runs it. Prints each part's
seconds and share, and the run's 1M-step wall time scaled from it. The table is in
docs/results/speed.md.
"""

from __future__ import annotations

import argparse
import functools
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

SAMPLING = "sampling (collect_rollouts, less the evaluations in it)"
_open: list[list[float]] = []  # the timed calls under way: [their inner calls' seconds]


def timed(owner: Any, name: str, spent: dict[str, float], label: str) -> None:
    """Wrap ``owner.name`` so that its calls' own seconds (less those of timed calls inside
    them: an evaluation runs inside a rollout's collection) add up in ``spent[label]``."""
    inner: Callable[..., Any] = getattr(owner, name)

    @functools.wraps(inner)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        _open.append([0.0])
        t0 = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            took = time.perf_counter() - t0
            nested = _open.pop()[0]
            spent[label] = spent.get(label, 0.0) + took - nested
            if _open:
                _open[-1][0] += took

    setattr(owner, name, wrapper)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("source", type=Path, help="a dataset folder (cloned first) or a policy")
    p.add_argument("--steps", type=int, default=200_000)
    args = p.parse_args(argv)
    from gymfg_il.rl.algorithm import FineTunePPO
    from gymfg_il.rl.config import PPORunConfig
    from gymfg_il.rl.grouped.algorithm import GroupedPPO
    from gymfg_il.rl.judge import Judge
    from gymfg_il.rl.run import train_ppo

    with tempfile.TemporaryDirectory() as tmp:
        policy = args.source
        if (policy / "meta").is_dir():
            policy = Path(tmp) / "bc"
            subprocess.run(
                [sys.executable, "-m", "gymfg_il.train", "bc", "--dataset", str(args.source),
                 "--out", str(policy), "--no-progress"],
                check=True, capture_output=True,
            )  # fmt: skip
        spent: dict[str, float] = {}
        timed(GroupedPPO, "collect_rollouts", spent, SAMPLING)
        timed(FineTunePPO, "train", spent, "updates (PPO.train)")
        timed(Judge, "__call__", spent, "evaluations (the curve, the kept actor's choice)")
        timed(Judge, "controller", spent, "the controller's evaluation")
        cfg = PPORunConfig(
            init=policy, steps=args.steps, turbulence="moderate", out=Path(tmp) / "ppo"
        )
        started = time.perf_counter()
        result = train_ppo(cfg)
        wall = time.perf_counter() - started
    spent["the rest (start, envs built, saving)"] = wall - sum(spent.values())
    print(f"train ppo, {result.steps:,} steps: {wall:.1f} s")
    for label, seconds in spent.items():
        print(f"  {label:<52} {seconds:7.1f} s  {seconds / wall:6.1%}")
    print(f"scaled to 1M steps: {wall * 1e6 / result.steps / 60:.1f} min")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
