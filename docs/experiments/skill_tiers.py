"""The table and plot of ``skill_tiers.sh``: each tier's demonstrations (grades, as the
card counts them), each pilot and each policy on the same held-out episodes, and the
controller beside them. Usage: python docs/experiments/skill_tiers.py OUT"""

from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

from gymfg_il.datasets.card import episode_columns
from gymfg_il.tasks.grades import GRADES

TIERS = ("novice", "okay", "expert")
POLICIES = (
    "novice",
    "okay",
    "expert",
    "mixed",
    "selected",
    "excellent",
    "weighted",
    "novice-shifted",
)


def row(name: str, r: dict) -> tuple[str, int, int, float, float, int]:
    eps = r["per_episode"]
    returns = [e["total_return"] for e in eps]
    ok = sum(bool(e["success"]) for e in eps)
    return name, ok, len(eps), sum(returns) / len(eps), min(returns), int(r["terminated"])


def main(out: Path) -> None:
    cols = episode_columns(out / "dataset")
    graded = Counter(zip(cols["gymfg/pilot"], cols["gymfg/grade"], strict=True))
    print("| demonstrations | " + " | ".join(GRADES) + " |")
    print("|---|" + "---|" * len(GRADES))
    for tier in TIERS:
        print(f"| {tier} | " + " | ".join(str(graded[(tier, g)]) for g in GRADES) + " |")
    rows = []
    for tier in TIERS:
        pilot = json.loads((out / f"eval-pilot-{tier}.json").read_text())["rows"][1]
        rows.append(row(f"pilot {tier}", pilot))
    policies = json.loads((out / "eval-policies.json").read_text())["rows"]
    rows.append(row("controller", policies[0]))
    for name, r in zip(POLICIES, policies[1:], strict=True):
        rows.append(row(f"BC {name}", r))
    print("\n| flown by | success | mean return | worst return | crashes |")
    print("|---|---|---|---|---|")
    for name, ok, n, mean, worst, crashed in rows:
        print(f"| {name} | {ok} of {n} | {mean:.1f} | {worst:.1f} | {crashed} |")
    _plot(rows, out / "skill_tiers.png")


def _plot(rows: list, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    names = [r[0] for r in rows]
    share = [100.0 * r[1] / r[2] for r in rows]
    colours = [
        "#7a7a7a" if n.startswith("pilot") or n == "controller" else "#2b6cb0" for n in names
    ]
    ax.bar(names, share, color=colours)
    ax.set_ylabel("success (%)")
    ax.set_ylim(0, 105)
    ax.set_title("BC from pilots of mixed skill (grey: the pilots and the controller)")
    ax.tick_params(axis="x", rotation=40)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"\nplot: {path}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
