"""One episode of the altitude, step by step: what the controller and each policy do with the
elevator and throttle, and what the airspeed, pitch and climb rate do.

    python docs/experiments/altitude_trace.py POLICY [POLICY ...] --seed 9507 \
        --turbulence moderate [--every 3]

Each agent flies the episode of ``--seed`` in the policies' own flight, in the air
``--turbulence`` gives (as ``eval`` flies them); a line every ``--every`` seconds and at the
end (with why the episode ended). The results: docs/results/rl.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gymfg_il.evaluation.config import EvalConfig
from gymfg_il.evaluation.plan import plan
from gymfg_il.sim.properties import INDEX

SHOWN = ("airspeed_kts", "pitch_deg", "vertical_speed_fps")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("policy", nargs="+", type=Path)
    parser.add_argument("--seed", type=int, default=9507)
    parser.add_argument("--every", type=float, default=3.0, help="seconds between lines")
    parser.add_argument("--turbulence", help="fly in this air (default: the first policy's)")
    args = parser.parse_args()
    cfg = EvalConfig(policy=args.policy, episodes=1, seed=args.seed, turbulence=args.turbulence)
    flight, agents, notes = plan(cfg)
    for note in notes:
        print(note)
    every = max(1, round(args.every * flight.agent_hz))
    for name, spec in agents.items():
        env = flight.make_env()
        agent = spec.make(env)
        obs, _ = env.reset(seed=args.seed)
        task = env.unwrapped.task
        print(f"\n{name}, seed {args.seed}")
        print("    t s   error ft  airspeed kt  pitch deg  climb ft/s  elevator  throttle")
        step, done = 0, False
        while not done:
            step += 1
            action = agent.act(obs)
            obs, _, terminated, truncated, info = env.step(action)
            state = env.unwrapped.world.slots[0].state
            done = terminated or truncated
            if step % every == 0 or done:
                error = task.error(float(state[INDEX[task.family.variable]]), step)
                speed, pitch, climb = (float(state[INDEX[v]]) for v in SHOWN)
                print(
                    f"{step / flight.agent_hz:7.1f} {error:10.1f} {speed:12.1f} {pitch:10.1f}"
                    f" {climb:11.1f} {action[1]:9.2f} {action[3]:9.2f}"
                )
            if terminated:
                print(f"    ended: {info.get('reason') or 'terminated'}")
        env.close()


if __name__ == "__main__":
    main()
