"""Every evaluated actor of a PPO run flown again: which actor each way of choosing keeps, and
how it flies on the held-out blocks.

    python -m gymfg_il.train ppo --init runs/rl/altitude/bc --turbulence moderate \
        --checkpoints --out RUN
    python docs/experiments/rl_checkpoints.py RUN [--check-seed 8000] [--check 64]

Each checkpoint (RUN/checkpoints/step-N) flies CHECK episodes from --check-seed (seeds no
choice saw) and the three held-out blocks the results page reports (9300, 9400, 9500, 16
each), in the run's own flight. The table gives, per checkpoint, the run's own curve (its
first 16 seeds) and its choice figure (curve.json), then both fresh figures; below it, the
held-out success of the actor each rule keeps: the best on the curve's 16 seeds, on the run's
select_episodes seeds (``train ppo``'s choice), on the CHECK seeds, and the best held out
(the ceiling no rule can pass). The results: docs/results/rl.md.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.evaluation.metrics import score_episode
from gymfg_il.evaluation.runner import evaluate
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.workers import Workers

BLOCKS = (9300, 9400, 9500)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path, help="a train ppo folder saved with --checkpoints")
    parser.add_argument("--check-seed", type=int, default=8000, help="first fresh seed")
    parser.add_argument("--check", type=int, default=64, help="fresh episodes a checkpoint")
    args = parser.parse_args()
    rl = json.loads((args.run / "curve.json").read_text())
    own = {p["step"]: p for p in rl["curve"]}
    held_seeds = [b + i for b in BLOCKS for i in range(16)]
    check_seeds = list(range(args.check_seed, args.check_seed + args.check))
    rows: dict[int, tuple[float, float, list[float]]] = {}  # check, held out, its blocks
    print("step       own 16  chosen on   check  held out (blocks)")
    with Workers(2) as pool:
        for step in sorted(own):
            path = args.run / "checkpoints" / f"step-{step}"
            spec = FlightSpec.from_dict(json.loads((path / "config.json").read_text())["spec"])
            seeds = check_seeds + held_seeds
            _, traces = evaluate(spec, {"p": AgentSpec.policy(path)}, seeds, pool)
            ok = [score_episode(t).success for t in traces["p"]]
            check, held = ok[: len(check_seeds)], ok[len(check_seeds) :]
            blocks = [100 * sum(held[16 * i : 16 * i + 16]) / 16 for i in range(len(BLOCKS))]
            rows[step] = (sum(check) / len(check), sum(held) / len(held), blocks)
            p = own[step]
            print(
                f"{step:>9,}  {100 * p['success']:5.0f}%  {100 * p['select_success']:5.0f}% "
                f"({p['chosen_on']})  {100 * rows[step][0]:5.0f}%  {100 * rows[step][1]:5.0f}% "
                + " / ".join(f"{b:.0f}" for b in blocks),
                flush=True,
            )
    first = sorted(own)  # ties go to the earlier actor, as train ppo's choice does
    kept = {
        "the curve's 16 seeds": max(
            first, key=lambda s: (own[s]["success"], own[s]["mean_return"])
        ),
        f"train ppo's choice ({rl['kept']['chosen_on']} seeds)": rl["kept"]["step"],
        f"the {args.check} fresh seeds": max(first, key=lambda s: rows[s][0]),
        "the held-out blocks (the ceiling)": max(first, key=lambda s: rows[s][1]),
    }
    print("\nheld out, the actor each rule keeps:")
    for rule, step in kept.items():
        blocks = " / ".join(f"{b:.0f}" for b in rows[step][2])
        print(f"  best on {rule:38s} step {step:>9,}: {100 * rows[step][1]:.0f}% ({blocks})")


if __name__ == "__main__":
    main()
