"""Ways for a cloned policy to remember, side by side on held-out seeds (docs/results/memory.md).

Each case collects autopilot demonstrations (`collect autopilot`, DART noise as given; the
`pilot` case: 30 of the synthetic pilot on the keyboard, who trims, with the pilot's row
beside the controller's), trains
every variant on them with `train bc`'s defaults otherwise, and flies the controller and every
policy on the same held-out seeds with `eval`. Printed per case and variant: success, return
over the controller's, crashes, the mean steady-state error, and the copycat probe (R^2 of each
action from the step's previous action alone, by least squares over every flown step; the
controller's own beside it).

    python docs/experiments/memory.py OUT [--cases 5-demos gusts pilot] [--tasks altitude heading]
        [--noise 0.05 0.1] [--variants mlp vertical loops chunk gru] [--episodes 16] [--seed 7000]
        [--demo-seed 100]

Variants: `mlp` (no memory), `vertical` (`--memory vertical`: the climb-rate and pitch
loops), `loops` (`--memory loops`: every loop), `chunk` (an observation window of 8
steps, one action: `--policy chunk --history 8 --chunk 1`), `gru` (`--policy gru`,
20 epochs: its default 60 takes ~20 min per case on two cores).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

os.environ.setdefault("HF_HUB_OFFLINE", "1")

CASES = {
    # name: (demonstrations, the air they are flown in, the air the policies are flown in)
    "5-demos": (5, "none", "none"),
    "gusts": (10, "none", "moderate"),
    "pilot": (30, "none", "none"),  # the synthetic pilot on the keyboard, who trims
}
VARIANTS = {
    "mlp": ["--memory", "none"],
    "vertical": ["--memory", "vertical"],
    "loops": ["--memory", "loops"],
    "chunk": ["--policy", "chunk", "--history", "8", "--chunk", "1"],
    "gru": ["--policy", "gru", "--epochs", "20"],
}


def run(*args: str) -> None:
    cmd = [sys.executable, "-m", *args]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")


def copycat(traces: list) -> float:
    """R^2 of each action from the previous one alone (least squares per axis, pooled)."""
    res = tot = 0.0
    for axis in range(4):
        prev = np.concatenate([t.actions[:-1, axis] for t in traces])
        now = np.concatenate([t.actions[1:, axis] for t in traces])
        if now.var() < 1e-12:
            continue
        a = np.c_[prev, np.ones_like(prev)]
        fit, *_ = np.linalg.lstsq(a, now, rcond=None)
        res += float(((now - a @ fit) ** 2).sum())
        tot += float(((now - now.mean()) ** 2).sum())
    return 1.0 - res / tot if tot else float("nan")


def case_rows(out: Path, case: str, task: str, noise: float, args: argparse.Namespace) -> None:
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.runner import run_eval

    demos, collect_air, eval_air = CASES[case]
    stem = data = out / f"{case}-{task}-noise{noise:g}"
    if case == "pilot":
        if not data.exists():
            run("gymfg_il.collect", "manual", "--pilot", "synthetic", "--device", "keyboard",
                "--task", task, "--episodes", str(demos), "--seed", "2000", "--out", str(data),
                "--no-progress")  # fmt: skip
        data = data / "dataset"
    elif not data.exists():
        run("gymfg_il.collect", "autopilot", "--task", task, "--episodes", str(demos),
            "--seed", str(args.demo_seed), "--noise", str(noise), "--turbulence", collect_air,
            "--out", str(data), "--no-progress")  # fmt: skip
    policies = []
    for variant in args.variants:
        folder = stem.with_name(stem.name + f"-{variant}")
        if not folder.exists():
            run("gymfg_il.train", "bc", "--dataset", str(data), "--out", str(folder),
                "--no-progress", *VARIANTS[variant])  # fmt: skip
        policies.append(folder)
    pilot = "synthetic" if case == "pilot" else None
    cfg = EvalConfig(
        policy=policies,
        episodes=args.episodes,
        seed=args.seed,
        workers=2,
        turbulence=eval_air,
        pilot=pilot,
    )
    result = run_eval(cfg)
    ctrl = result.rows[0]
    agents = ["controller", *(["pilot"] if pilot else []), *args.variants]
    for row, variant in zip(result.rows, agents, strict=True):
        traces = result.traces[row["agent"]]
        ret = row["mean_return"] / ctrl["mean_return"]
        crashes = sum(t.terminated for t in traces)
        print(
            f"| {case} | {task} | {noise:g} | {variant} | {row['success_rate']:.0%} | "
            f"{ret:.1%} | {crashes} | {row['steady_state_error']:.2f} | {copycat(traces):.3f} |",
            flush=True,
        )


def main() -> None:
    from gymfg_il.collectors.config import CollectConfig

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder for the datasets and policies")
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--tasks", nargs="+", default=["altitude", "heading"])
    parser.add_argument(
        "--noise", nargs="+", type=float, default=None,
        help="DART noise (default: collect's, each task's own)",
    )  # fmt: skip
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--episodes", type=int, default=16)
    parser.add_argument("--seed", type=int, default=7000, help="first held-out seed")
    parser.add_argument("--demo-seed", type=int, default=100, help="first demonstration's seed")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    print("| case | task | noise | agent | success | return | crashes | ss error | copycat |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for case in args.cases:
        for task in args.tasks:
            own = CollectConfig(task=task).dart_noise()
            for noise in args.noise or [own]:
                case_rows(args.out, case, task, noise, args)


if __name__ == "__main__":
    main()
