"""The table and curves of rl_finetune.sh: python docs/experiments/rl_finetune.py OUT [PNG].

For each task folder under OUT: success and return on the held-out seeds (eval.json) of the
controller, the BC start, the fine-tuned policy and PPO from scratch; the fine-tuning's lowest
evaluation against its start (the collapse check, on the run's own 16 seeds, every 50k
steps); env steps and wall time. With several fine-tuning seeds (``ppo``, ``ppo-s1``, ...,
rl_finetune.sh's SEEDS), the fine-tuned cell is the worst run (by held-out success) with the
mean over the runs beside it, and the collapse check the worst of them. The curves go to PNG
(default docs/images/rl_curves.png).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

TASKS = ("altitude", "heading", "approach", "turn")


def _rows(folder: Path) -> dict[str, dict]:
    rows = json.loads((folder / "eval.json").read_text())["rows"]
    return {r["agent"].split(":")[-1]: r for r in rows}


def _tuned(folder: Path) -> list[str]:
    """The fine-tuning runs of a task folder: ppo (seed 0), then ppo-s1, ppo-s2, ..."""
    names = [p.name for p in folder.glob("ppo-s*") if (p / "curve.json").is_file()]
    return ["ppo", *sorted(names, key=lambda n: int(n.removeprefix("ppo-s")))]


def _curve(folder: Path) -> dict | None:
    path = folder / "curve.json"
    return json.loads(path.read_text()) if path.is_file() else None


def table(out: Path) -> list[str]:
    lines = [
        "| task | air | controller | BC start | fine-tuned | from scratch | lowest - start "
        "| steps | wall time (fine-tune, scratch) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for task in TASKS:
        folder = out / task
        if not (folder / "eval.json").is_file():
            continue
        rows = _rows(folder)
        ppo, scratch = _curve(folder / "ppo"), _curve(folder / "scratch")
        air = rows["controller"]["spec"]["turbulence"]

        def cell(name: str, rows: dict[str, dict] = rows) -> str:
            r = rows.get(name)
            if r is None:
                return "-"
            crashed = f", {r['terminated']} ended early" if r["terminated"] else ""
            return f"{100 * r['success_rate']:.0f}% ({r['mean_return']:.0f}{crashed})"

        runs = [name for name in _tuned(folder) if name in rows]
        tuned = cell("ppo")
        if len(runs) > 1:
            worst = min(runs, key=lambda name: rows[name]["success_rate"])
            mean = sum(rows[name]["success_rate"] for name in runs) / len(runs)
            tuned = f"worst {cell(worst)}; mean {100 * mean:.0f}% of {len(runs)} seeds"
        dips = []
        for name in runs:
            c = _curve(folder / name)
            if c:
                start = c["curve"][0]["success"]
                dips.append(min(p["success"] for p in c["curve"]) - start)
        dip = f"{100 * min(dips):+.0f} pp" if dips else "-"
        steps = f"{ppo['steps']:,}" if ppo else "-"
        walls = ", ".join(f"{c['wall_s'] / 60:.0f} min" if c else "-" for c in (ppo, scratch))
        lines.append(
            f"| {task} | {air} | {cell('controller')} | {cell('bc')} | {tuned} | "
            f"{cell('scratch')} | {dip} | {steps} | {walls} |"
        )
    return lines


def plot(out: Path, png: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    tasks = [t for t in TASKS if _curve(out / t / "ppo")]
    fig, axes = plt.subplots(1, len(tasks), figsize=(4 * len(tasks), 3.4), squeeze=False)
    for ax, task in zip(axes[0], tasks, strict=True):
        runs = _tuned(out / task)
        for name in (*runs, "scratch"):
            c = _curve(out / task / name)
            if c is None:
                continue
            steps = [p["step"] for p in c["curve"]]
            label = "from scratch" if name == "scratch" else "fine-tuned"
            if name != "scratch" and len(runs) > 1:
                label += f", seed {c['settings']['seed']}"
            ax.plot(steps, [100 * p["success"] for p in c["curve"]],
                    "-s" if name == "scratch" else "-o", ms=3, label=label)  # fmt: skip
        c = _curve(out / task / "ppo")
        ax.axhline(100 * c["curve"][0]["success"], color="grey", ls="--", label="BC start")
        ax.axhline(100 * c["controller"]["success"], color="green", ls=":", label="controller")
        ax.set_title(task)
        ax.set_xlabel("env steps")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x / 1000:.0f}k"))
        ax.set_ylim(-5, 105)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("success % (16 seeds)")
    axes[0][0].legend(fontsize=8)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=90)
    print(f"curves written to {png}")


def main() -> int:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "runs/experiments/rl-finetune")
    png = Path(sys.argv[2] if len(sys.argv) > 2 else "docs/images/rl_curves.png")
    print("\n".join(table(out)))
    plot(out, png)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
