"""``python -m gymfg_il.eval``: fly agents on the same seeded cases and score them.

The task's physics-based controller always flies; each ``--policy`` flies beside it. Every
agent meets the same seeds, hence the same start states and targets.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

TASKS = ("altitude", "roll", "pitch", "heading", "airspeed", "level")


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.eval",
        description="Fly agents on seeded episodes of a GymFG task and compare them: a table "
        "in the terminal, optionally JSON rows and the paper's Figure 1 (per episode: control "
        "signal, target vs controlled variable, reward).",
    )
    add = p.add_argument
    add(
        "--policy",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="a trained policy (checkpoint folder) to fly beside the controller; repeatable; "
        "task and aircraft default to the policy's",
    )
    add("--task", choices=TASKS, help="task family (default: the policy's, else altitude)")
    add(
        "--dynamic",
        action="store_true",
        help="moving targets (the family's dynamic task) instead of fixed ones",
    )
    add(
        "--aircraft",
        help="JSBSim model: c172p, f15, A320 or any other JSBSim ships "
        "(default: the policy's, else c172p)",
    )
    add("--episodes", type=int, default=10, help="episodes per agent (default: 10)")
    add(
        "--seed",
        type=int,
        default=0,
        help="seed of the first episode; episode i uses seed+i (default: 0; the bundled "
        "demonstrations use seeds from 1000, so these are held out)",
    )
    add("--episode-time", type=float, default=90.0, help="episode length in seconds (default: 90)")
    add("--agent-hz", type=int, default=10, help="agent rate in Hz, a divisor of 120 (default: 10)")
    add(
        "--workers",
        type=int,
        default=1,
        help="worker processes flying episodes in parallel; results are identical to one "
        "worker (default: 1)",
    )
    add("--json", type=Path, metavar="PATH", help="write the rows as JSON to PATH")
    add("--plots", type=Path, metavar="DIR", help="write Figure-1 plots (one PNG per agent) to DIR")
    add("--plot-episodes", type=int, default=4, help="episodes (rows) per plot (default: 4)")
    add("--no-progress", action="store_true", help="no progress bar")
    args = p.parse_args(argv)
    if args.episodes < 1:
        p.error(f"--episodes must be >= 1, got {args.episodes}")
    if args.workers < 1:
        p.error(f"--workers must be >= 1, got {args.workers}")
    return args


def add_ratios(rows: list[dict[str, Any]]) -> None:
    """Each agent's mean return and success rate as a share of the controller's (first row)."""
    base = rows[0]
    for row in rows:
        for key, ratio in (("mean_return", "return_ratio"), ("success_rate", "success_ratio")):
            ref, value = float(base[key]), float(row[key])
            row[ratio] = value / ref if ref else float("nan")


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from tqdm import tqdm

    from gymfg_il.errors import GymFGError
    from gymfg_il.evaluation.metrics import summarize
    from gymfg_il.evaluation.parallel import AgentSpec, EnvSpec, Workers, fly_many
    from gymfg_il.evaluation.report import table
    from gymfg_il.evaluation.rollout import PRIMARY_CONTROL
    from gymfg_il.policies.agent import PolicyAgent
    from gymfg_il.viz.plots import figure1

    try:
        metas = [AgentSpec.policy(path).meta() for path in args.policy]
        first = metas[0] if metas else {}
        spec = EnvSpec(
            task=args.task or first.get("task") or "altitude",
            aircraft=args.aircraft or first.get("aircraft") or "c172p",
            dynamic=args.dynamic or bool(first.get("dynamic", False)),
            agent_hz=args.agent_hz,
            episode_time_s=args.episode_time,
        )
        env = spec.make()
        for meta in metas:
            PolicyAgent(None, meta).check_observation(env.observation_names)
        model = env.aircraft.model
        env.close()
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    agents = {"controller": AgentSpec.controller()}
    for path in args.policy:
        agents[f"policy:{path.name}"] = AgentSpec.policy(path)
    seeds = list(range(args.seed, args.seed + args.episodes))
    task_name = spec.task + ("-dynamic" if spec.dynamic else "")
    rows, flown = [], {}
    # one pool for every agent, started before the progress bar starts its thread
    with Workers(min(args.workers, len(seeds))) as workers:
        bar = tqdm(
            total=len(agents) * len(seeds),
            desc="episodes",
            unit="ep",
            disable=args.no_progress,
            file=sys.stderr,
        )
        for name, agent in agents.items():
            bar.set_postfix_str(name)
            flown[name] = fly_many(spec, agent, seeds, workers, progress=lambda: bar.update(1))
            rows.append(summarize(name, task_name, model, flown[name]))
    bar.close()
    add_ratios(rows)
    print(
        f"{task_name} on {model}: {len(seeds)} episodes of {args.episode_time:g} s, "
        f"seeds {seeds[0]}..{seeds[-1]}\n"
    )
    print(table(rows))
    for row in rows[1:]:
        print(
            f"\n{row['agent']} / controller: return {row['return_ratio']:.1%}, "
            f"success {row['success_ratio']:.1%}"
        )
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"rows": rows}, indent=2))
        print(f"\nrows written to {args.json}")
    if args.plots:
        for name, episodes in flown.items():
            path = args.plots / f"{task_name}_{model}_{name.replace(':', '-')}.png"
            figure1(
                episodes[: args.plot_episodes],
                PRIMARY_CONTROL[spec.task],
                f"{name}: {task_name} on {model}",
                path,
            )
            print(f"plot written to {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
