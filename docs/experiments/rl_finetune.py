"""The table and curves of rl_finetune.sh: python docs/experiments/rl_finetune.py OUT [PNG].

For each task folder under OUT: success and return on the held-out seeds (eval.json) of the
controller, the BC start, the fine-tuned policy and PPO from scratch; the fine-tuning's lowest
evaluation against its start (the collapse check, on the run's own 16 seeds, every 50k
steps); env steps and wall time. The curves go to PNG (default docs/images/rl_curves.png).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

TASKS = ("altitude", "heading", "approach", "turn")


def _rows(folder: Path) -> dict[str, dict]:
    rows = json.loads((folder / "eval.json").read_text())["rows"]
    return {r["agent"].split(":")[-1]: r for r in rows}


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

        dip = "-"
        if ppo:
            start = ppo["curve"][0]["success"]
            low = min(p["success"] for p in ppo["curve"])
            dip = f"{100 * (low - start):+.0f} pp"
        steps = f"{ppo['steps']:,}" if ppo else "-"
        walls = ", ".join(f"{c['wall_s'] / 60:.0f} min" if c else "-" for c in (ppo, scratch))
        lines.append(
            f"| {task} | {air} | {cell('controller')} | {cell('bc')} | {cell('ppo')} | "
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
        for name, style in (("ppo", "-o"), ("scratch", "-s")):
            c = _curve(out / task / name)
            if c is None:
                continue
            steps = [p["step"] for p in c["curve"]]
            ax.plot(steps, [100 * p["success"] for p in c["curve"]], style, ms=3,
                    label="fine-tuned" if name == "ppo" else "from scratch")  # fmt: skip
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
