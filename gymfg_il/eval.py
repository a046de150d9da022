"""``python -m gymfg_il.eval``: fly agents on seeded episodes of a GymFG task and compare them.

The task's physics-based controller always flies; each ``--policy`` flies beside it, on its
own flight (aircraft, task, rate and episode time, as it was trained) unless a flag changes
it. Every agent meets the same seeds, hence the same start states and targets. Prints a table,
and optionally writes JSON rows and the paper's Figure 1 (per episode: control signal, target
vs controlled variable, reward).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    from gymfg_il import cli
    from gymfg_il.envs.options import TASK_OWN_TIME, unset_values
    from gymfg_il.evaluation.config import EvalConfig

    p = cli.parser("python -m gymfg_il.eval", __doc__)
    unset = {**unset_values(), "episode_time_s": TASK_OWN_TIME}
    cli.add_fields(p, EvalConfig, shown={k: f"the policy's, else {v}" for k, v in unset.items()})
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    from gymfg_il import cli
    from gymfg_il.evaluation.config import EvalConfig

    args = parse_args(argv)
    return cli.run(lambda: _main(cli.build(EvalConfig, args), not args.no_progress))


def _main(cfg: object, show_progress: bool) -> int:
    from gymfg_il import cli
    from gymfg_il.datasets.lerobot_api import hub_offline
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.report import ratio_line, table
    from gymfg_il.evaluation.runner import run_eval

    assert isinstance(cfg, EvalConfig)
    hub_offline()

    def progress(total: int) -> Callable[[str], None]:
        bar = cli.progress_bar(total, "episodes", "ep", show_progress)

        def tick(name: str) -> None:
            bar.set_postfix_str(name, refresh=False)
            bar.update(1)
            if bar.n == total:
                bar.close()

        return tick

    run = run_eval(cfg, progress)
    for note in run.notes:
        print(note, file=sys.stderr)
    flight, seeds = run.flight, cfg.seeds
    air = "" if flight.turbulence == "none" else f", {flight.turbulence} turbulence"
    air += f", {flight.wind_kt:g} kt wind" if flight.wind_kt else ""
    print(
        f"{flight.task_label} on {flight.aircraft} at {flight.agent_hz} Hz{air}: {len(seeds)} "
        f"episodes of {flight.episode_time_s:g} s, seeds {seeds[0]}..{seeds[-1]}\n"
    )
    print(table(run.rows))
    for row in run.rows[1:]:
        print(f"\n{ratio_line(row, run.rows[0])}")
    pilots = [r for r in run.rows if str(r["agent"]).startswith("pilot:")]
    for pilot in pilots:  # each policy beside the pilot it was scored against, too
        for row in run.rows:
            if str(row["agent"]).startswith("policy:"):
                print(ratio_line(row, pilot))
    for path in run.written:
        print(f"{'rows' if path.suffix == '.json' else 'plot'} written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
