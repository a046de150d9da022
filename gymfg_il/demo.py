"""``python -m gymfg_il.demo``: fly the default task with its controller and print a table.

The quick start's main job until the learning loop lands: a c172p flies the static altitude
task under its PID autopilot on a few seeded targets.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.tasks.library import TASK_FAMILIES


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(
        prog="python -m gymfg_il.demo",
        description="Fly a GymFG task with its physics-based controller on seeded episodes "
        "and print one row per episode (target, final value, error, return, outcome).",
    )
    p.add_argument(
        "--task",
        default="altitude",
        choices=sorted(TASK_FAMILIES),
        help="task family (default: altitude)",
    )
    p.add_argument("--aircraft", default="c172p", help="JSBSim model: c172p, f15, A320, ...")
    p.add_argument("--dynamic", action="store_true", help="moving targets instead of fixed ones")
    p.add_argument("--episodes", type=int, default=3, help="episodes to fly (default: 3)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first episode (default: 0)")
    p.add_argument("--episode-time", type=float, default=90.0, help="seconds per episode")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    env = AircraftEnv(
        args.task, args.aircraft, dynamic=args.dynamic, episode_time_s=args.episode_time
    )
    pilot = controller_for(
        env.task, env.aircraft.model, env.dt, env.aircraft.profile.cruise_throttle
    )
    names = env.observation_names
    var = names[-2].removesuffix("_target") if names[-2].endswith("_target") else None
    print(
        f"{args.task} task, {env.aircraft.model}, {args.episodes} episodes of "
        f"{args.episode_time:g} s at {env.world.config.agent_hz} Hz, PID autopilot\n"
    )
    header = (
        f"{'episode':>7} {'seed':>5} {'target':>10} {'final':>10} {'|error|':>8} "
        f"{'return':>8} {'outcome':>10}"
    )
    print(header)
    print("-" * len(header))
    started = time.perf_counter()
    steps = 0
    for ep in range(args.episodes):
        seed = args.seed + ep
        obs, _info = env.reset(seed=seed)
        pilot.reset(seed)
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, step_info = env.step(pilot.act(obs))
            total += reward
            steps += 1
            done = terminated or truncated
        outcome = step_info.get("reason", "crash") if terminated else "time limit"
        if var is not None:
            target, error = float(obs[-2]), float(obs[-1])
            final = target - error
            print(
                f"{ep:>7} {seed:>5} {target:>10.1f} {final:>10.1f} {abs(error):>8.2f} "
                f"{total:>8.1f} {outcome:>10}"
            )
        else:
            print(f"{ep:>7} {seed:>5} {'-':>10} {'-':>10} {'-':>8} {total:>8.1f} {outcome:>10}")
    elapsed = time.perf_counter() - started
    print(
        f"\n{steps} steps in {elapsed:.1f} s ({steps / elapsed:,.0f} steps/s, "
        f"{steps * env.dt / elapsed:,.0f}x real time)"
    )
    env.close()
    return 0 if np.isfinite(total) else 1


if __name__ == "__main__":
    raise SystemExit(main())
