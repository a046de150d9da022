"""Online lockstep: this working tree against a git revision, in alternating runs.

    python -m benchmarks.compare_online afae2c1 --rounds 6

Each round runs one lockstep (``benchmarks.online``, or ``benchmarks/run.py``'s ``online`` in
revisions from before the benchmarks were split) with the revision's code (checked out in a
temporary git worktree) and once with this tree's, so that a slow spell of a shared machine
hits both sides. Prints every pair, the medians and the best.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def rate(tree: Path, teams: int, steps: int) -> float:
    """One lockstep run with ``tree``'s code (its server and clients import that tree)."""
    if (tree / "benchmarks" / "online.py").is_file():
        cmd = [sys.executable, "-m", "benchmarks.online", "--rate", str(teams), str(steps)]
    else:  # a revision from before the split: its run.py held online()
        code = f"import run; print(run.online({teams}, {steps}))"
        cmd = [sys.executable, "-c", code]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tree), str(tree / "benchmarks")])}
    out = subprocess.run(cmd, env=env, cwd=tree, check=True, capture_output=True, text=True).stdout
    return float(out.split()[-1])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("revision", help="the git revision to compare against (e.g. HEAD~3)")
    p.add_argument("--rounds", type=int, default=6, help="alternating rounds (default: 6)")
    p.add_argument("--teams", type=int, default=2, help="teams in lockstep (default: 2)")
    p.add_argument("--steps", type=int, default=2000, help="steps per run (default: 2000)")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "base"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(base), args.revision],
            check=True,
        )
        try:
            pairs = []
            for i in range(args.rounds):
                pair = (rate(base, args.teams, args.steps), rate(ROOT, args.teams, args.steps))
                pairs.append(pair)
                print(f"round {i + 1}: {args.revision} {pair[0]:7,.0f}  this tree {pair[1]:7,.0f}")
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)])
    for name, rates in (
        (args.revision, [a for a, _ in pairs]),
        ("this tree", [b for _, b in pairs]),
    ):
        print(
            f"{name:>12}: median {statistics.median(rates):7,.0f}, best {max(rates):7,.0f} steps/s"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
