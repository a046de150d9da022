"""``python -m gymfg_il.demo``: the whole imitation-learning loop on the bundled default.

1. demonstrations: the bundled sample dataset (autopilot, altitude task, c172p), collected
   again by its recipe if it is missing;
2. ``train bc``: an MLP policy on it;
3. ``eval``: the policy against the controller on held-out seeds (the demonstrations used
   seeds from 1000; evaluation uses 0..N-1);
4. a report (table, JSON, Figure-1 plots, loss curve) written under ``runs/`` and its path
   printed.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

RECIPE = Path("collectors/sample.toml")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.demo",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--dataset",
        type=Path,
        default=Path("datasets/sample-altitude-c172p/dataset"),
        help="demonstrations to learn from (default: the bundled sample)",
    )
    p.add_argument("--epochs", type=int, default=30, help="training epochs (default: 30)")
    p.add_argument(
        "--episodes", type=int, default=10, help="held-out evaluation episodes (default: 10)"
    )
    p.add_argument(
        "--workers", type=int, default=2, help="evaluation worker processes (default: 2)"
    )
    p.add_argument(
        "--runs",
        type=Path,
        default=Path("runs"),
        help="where the report folder goes (default: runs/)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from gymfg_il import collect, train
    from gymfg_il import eval as evaluate

    started = time.perf_counter()
    quiet = ["--no-progress"] if args.no_progress else []
    run = args.runs / time.strftime("%Y%m%d-%H%M%S")
    run.mkdir(parents=True, exist_ok=True)
    if not (args.dataset / "meta" / "info.json").is_file():
        print(f"[1/3] {args.dataset} is missing: collecting it with {RECIPE}", flush=True)
        out = args.dataset.parent
        if (
            collect.main([str(RECIPE), "--out", str(out), "--workers", str(args.workers), *quiet])
            != 0
        ):
            return 1
    else:
        print(f"[1/3] demonstrations: {args.dataset}", flush=True)
    policy = run / "policy"
    print(f"[2/3] behaviour cloning -> {policy}", flush=True)
    if (
        train.main(
            [
                "bc",
                "--dataset",
                str(args.dataset),
                "--out",
                str(policy),
                "--epochs",
                str(args.epochs),
                *quiet,
            ]
        )
        != 0
    ):
        return 1
    print(f"[3/3] evaluating against the controller on {args.episodes} held-out seeds", flush=True)
    if (
        evaluate.main(
            [
                "--policy",
                str(policy),
                "--episodes",
                str(args.episodes),
                "--workers",
                str(args.workers),
                "--json",
                str(run / "eval.json"),
                "--plots",
                str(run / "plots"),
                *quiet,
            ]
        )
        != 0
    ):
        return 1
    write_report(run, policy, time.perf_counter() - started)
    print(f"\nreport: {run / 'report.md'}  ({time.perf_counter() - started:.0f} s in all)")
    return 0


def write_report(run: Path, policy: Path, seconds: float) -> None:
    from gymfg_il.evaluation.report import table

    rows = json.loads((run / "eval.json").read_text())["rows"]
    meta = json.loads((policy / "config.json").read_text())
    shutil.copy(policy / "loss.png", run / "loss.png")
    plots = sorted(p.relative_to(run) for p in (run / "plots").glob("*.png"))
    lines = [
        f"# GymFG-IL run {run.name}",
        "",
        f"Behaviour cloning ({meta['type']}) on `{meta['dataset']}` "
        f"({meta['train']['frames']} training frames, {meta['train']['epochs']} epochs), "
        f"evaluated on {rows[0]['episodes']} held-out seeds of the {rows[0]['task']} task on "
        f"{rows[0]['aircraft']}.",
        "",
        "```",
        table(rows),
        "```",
        "",
        *[
            f"- {r['agent']} / controller: return {r['return_ratio']:.1%}, success "
            f"{r['success_ratio']:.1%}"
            for r in rows[1:]
        ],
        "",
        "![loss](loss.png)",
        "",
        *[f"![{p.stem}]({p})" for p in plots],
        "",
        f"Made by `python -m gymfg_il.demo` in {seconds:.0f} s.",
    ]
    (run / "report.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
