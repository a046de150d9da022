"""``python -m gymfg_il.demo``: the whole imitation-learning loop on the bundled default.

1. demonstrations: the bundled sample dataset (autopilot, altitude task, c172p), collected
   again by its recipe if it is missing;
2. behaviour cloning: an MLP policy on it;
3. evaluation: the policy against the controller on held-out seeds (the demonstrations used
   seeds from 1000; evaluation uses 0..N-1);
4. a report (table, JSON, Figure-1 plots, loss curve) written under ``runs/<time>/`` and its
   path printed; the policy is ``runs/<time>/bc-<type>`` (``bc-mlp``), its name in the table.

Nothing is written until the demonstrations are at hand: outside the checkout, where neither
the bundled sample nor its recipe is, the demo says so and leaves no run folder behind.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from gymfg_il.learning.config import DEFAULT_DATASET, EPOCHS_AUTOPILOT

RECIPE = Path("collectors/sample.toml")


@dataclass
class DemoConfig:
    """The demo run.

    Attributes:
        dataset: demonstrations to learn from (the bundled sample by default).
        epochs: training epochs (train bc's default).
        episodes: held-out evaluation episodes.
        workers: evaluation worker processes.
        runs: where the report folder goes.
        progress: progress bars.
    """

    dataset: Path = DEFAULT_DATASET
    epochs: int = EPOCHS_AUTOPILOT
    episodes: int = 10
    workers: int = 2
    runs: Path = Path("runs")
    progress: bool = True

    def __post_init__(self) -> None:
        from gymfg_il.errors import ConfigError

        bad = [
            f"{k}={getattr(self, k)!r}"
            for k in ("epochs", "episodes", "workers")
            if isinstance(getattr(self, k), bool) or not isinstance(getattr(self, k), int)
            or getattr(self, k) < 1
        ]  # fmt: skip
        if bad:
            raise ConfigError(f"demo: {', '.join(bad)} must be integers >= 1")


def main(argv: list[str] | None = None) -> int:
    from gymfg_il import cli

    p = cli.parser("python -m gymfg_il.demo", __doc__)
    cli.add_fields(p, DemoConfig)
    args = p.parse_args(argv)
    return cli.run(lambda: run(cli.build(DemoConfig, args)))


def _bar(show: bool, unit: str) -> Callable[[int], Callable[..., None]]:
    from gymfg_il import cli

    def progress(total: int) -> Callable[..., None]:
        bar = cli.progress_bar(total, unit + "s", unit, show)

        def tick(*_: object) -> None:
            bar.update(1)
            if bar.n == total:
                bar.close()

        return tick

    return progress


def run(cfg: DemoConfig) -> int:
    from gymfg_il.datasets.lerobot_api import hub_offline
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.runner import run_eval
    from gymfg_il.learning.bc import train_bc
    from gymfg_il.learning.config import TrainConfig, validation_words

    hub_offline()
    started = time.perf_counter()
    if not (cfg.dataset / "meta" / "info.json").is_file():
        from gymfg_il.collectors.autopilot import collect_autopilot
        from gymfg_il.collectors.config import CollectConfig
        from gymfg_il.errors import ConfigError

        if not RECIPE.is_file():
            raise ConfigError(
                f"no demonstrations at {cfg.dataset} and no recipe at {RECIPE} to collect them: "
                "run the demo in the GymFG-IL checkout (make demo), or give --dataset DIR"
            )
        print(f"[1/3] {cfg.dataset} is missing: collecting it with {RECIPE}", flush=True)
        recipe = CollectConfig.from_recipe(RECIPE, out=cfg.dataset.parent)
        collect_autopilot(recipe, cfg.workers, _bar(cfg.progress, "episode"))
    else:
        print(f"[1/3] demonstrations: {cfg.dataset}", flush=True)
    run_dir = cfg.runs / time.strftime("%Y%m%d-%H%M%S")
    run_dir.mkdir(parents=True, exist_ok=True)
    train = TrainConfig(dataset=cfg.dataset, epochs=cfg.epochs)
    # the folder names the policy in the table and plots: policy:bc-mlp
    policy = run_dir / f"bc-{train.policy.type}"
    train = dataclasses.replace(train, out=policy)
    print(f"[2/3] behaviour cloning -> {policy}", flush=True)
    epoch_tick = _bar(cfg.progress, "epoch")(cfg.epochs)
    trained = train_bc(train, lambda *_: epoch_tick())
    held = validation_words(trained.val_loss[-1], trained.meta["train"]["val_frames"])
    print(f"      {held}", flush=True)
    print(f"[3/3] evaluating against the controller on {cfg.episodes} held-out seeds", flush=True)
    evaluation = EvalConfig(
        policy=[policy],
        episodes=cfg.episodes,
        workers=cfg.workers,
        json=run_dir / "eval.json",
        plots=run_dir / "plots",
    )
    result = run_eval(evaluation, _bar(cfg.progress, "episode"))
    write_report(run_dir, policy, result.rows, time.perf_counter() - started)
    from gymfg_il.evaluation.report import ratio_line, table

    print(table(result.rows))
    for row in result.rows[1:]:
        print(f"\n{ratio_line(row, result.rows[0])}")
    print(f"\nreport: {run_dir / 'report.md'}  ({time.perf_counter() - started:.0f} s in all)")
    return 0


def write_report(run: Path, policy: Path, rows: list[dict[str, object]], seconds: float) -> None:
    from gymfg_il.evaluation.report import ratio_line, table

    meta = json.loads((policy / "config.json").read_text())
    shutil.copy(policy / "loss.png", run / "loss.png")
    plots = sorted(p.relative_to(run) for p in (run / "plots").glob("*.png"))
    lines = [
        f"# GymFG-IL run {run.name}",
        "",
        f"Behaviour cloning ({meta['type']}) on `{meta['dataset']}` "
        f"({meta['train']['train_frames']} training frames, {meta['train']['epochs']} epochs), "
        f"evaluated on {rows[0]['episodes']} held-out seeds of the {rows[0]['task']} task on "
        f"{rows[0]['aircraft']} at {rows[0]['agent_hz']} Hz.",
        "",
        "```",
        table(rows),
        "```",
        "",
        *[f"- {ratio_line(r, rows[0])}" for r in rows[1:]],
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
