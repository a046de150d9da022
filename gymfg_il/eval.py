"""``python -m gymfg_il.eval``: fly agents on the same seeded cases and score them.

With no ``--policy`` it flies the task's physics-based controller. Every agent meets the same
seeds, hence the same start states and targets.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

TASKS = ("altitude", "roll", "pitch", "heading", "airspeed", "level")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.eval",
        description="Fly agents on seeded episodes of a GymFG task and compare them: a table "
        "in the terminal, optionally JSON rows and the paper's Figure 1 (per episode: control "
        "signal, target vs controlled variable, reward).",
    )
    p.add_argument(
        "--task", default="altitude", choices=TASKS, help="task family (default: altitude)"
    )
    p.add_argument(
        "--dynamic",
        action="store_true",
        help="moving targets (the family's dynamic task) instead of fixed ones",
    )
    p.add_argument(
        "--aircraft",
        default="c172p",
        help="JSBSim model: c172p, f15, A320 or any other JSBSim ships",
    )
    p.add_argument("--episodes", type=int, default=10, help="episodes per agent (default: 10)")
    p.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the first episode; episode i uses seed+i (default: 0)",
    )
    p.add_argument(
        "--episode-time", type=float, default=90.0, help="episode length in seconds (default: 90)"
    )
    p.add_argument(
        "--agent-hz", type=int, default=10, help="agent rate in Hz, a divisor of 120 (default: 10)"
    )
    p.add_argument("--json", type=Path, metavar="PATH", help="write the rows as JSON to PATH")
    p.add_argument(
        "--plots", type=Path, metavar="DIR", help="write Figure-1 plots (one PNG per agent) to DIR"
    )
    p.add_argument(
        "--plot-episodes", type=int, default=4, help="episodes (rows) per plot (default: 4)"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = p.parse_args(argv)
    if args.episodes < 1:
        p.error(f"--episodes must be >= 1, got {args.episodes}")
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from tqdm import tqdm

    from gymfg_il.controllers.autopilot import controller_for
    from gymfg_il.envs.single import AircraftEnv
    from gymfg_il.errors import GymFGError
    from gymfg_il.evaluation.metrics import summarize
    from gymfg_il.evaluation.report import table
    from gymfg_il.evaluation.rollout import PRIMARY_CONTROL, fly_episodes
    from gymfg_il.viz.plots import figure1

    try:
        env = AircraftEnv(
            args.task,
            args.aircraft,
            dynamic=args.dynamic,
            agent_hz=args.agent_hz,
            episode_time_s=args.episode_time,
        )
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    model = env.aircraft.model
    agents = {
        "controller": controller_for(env.task, model, env.dt, env.aircraft.profile.cruise_throttle)
    }
    seeds = list(range(args.seed, args.seed + args.episodes))
    task_name = args.task + ("-dynamic" if args.dynamic else "")
    rows, flown = [], {}
    bar = tqdm(
        total=len(agents) * len(seeds),
        desc="episodes",
        unit="ep",
        disable=args.no_progress,
        file=sys.stderr,
    )
    for name, agent in agents.items():
        bar.set_postfix_str(name)
        flown[name] = fly_episodes(env, agent, seeds, progress=lambda: bar.update(1))
        rows.append(summarize(name, task_name, model, flown[name]))
    bar.close()
    env.close()
    print(
        f"{task_name} on {model}: {len(seeds)} episodes of {args.episode_time:g} s, "
        f"seeds {seeds[0]}..{seeds[-1]}\n"
    )
    print(table(rows))
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"rows": rows}, indent=2))
        print(f"\nrows written to {args.json}")
    if args.plots:
        for name, episodes in flown.items():
            path = args.plots / f"{task_name}_{model}_{name}.png"
            figure1(
                episodes[: args.plot_episodes],
                PRIMARY_CONTROL[args.task],
                f"{name}: {task_name} on {model}",
                path,
            )
            print(f"plot written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
