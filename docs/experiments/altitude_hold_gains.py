"""What the c172p's altitude hold needs in moderate turbulence: the controller flown with its
altitude loop changed, on the held-out blocks the RL results report.

    python docs/experiments/altitude_hold_gains.py [--turbulence moderate] [--episodes 16]

Three gain sets of the controller (``controllers.gains``), each on blocks 9300, 9400 and 9500
(16 episodes each): its own; its own without the climb loop's integral (the altitude loop then
maps the state to the elevator with no memory, as a cloned MLP does); and that memoryless loop
with a firmer altitude-to-climb gain and climb gain. Prints success per block and the mean
error over the last 10 s (the verdict's, its tolerance 50 ft). Each set flies in this process
(one worker), its gains set in ``GAINS`` for the c172p while it flies. The results:
docs/results/rl.md.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np

from gymfg_il.controllers import gains as gains_module
from gymfg_il.envs.options import FlightOptions
from gymfg_il.evaluation.runner import evaluate
from gymfg_il.rollout.agents import AgentSpec

BLOCKS = (9300, 9400, 9500)


def variants() -> dict[str, gains_module.Gains]:
    own = gains_module.GAINS["c172p"]
    kp = own.climb[0]
    return {
        f"own (climb {own.climb}, altitude->climb {own.altitude_to_climb})": own,
        "no climb integral": replace(own, climb=(kp, 0.0, 0.0)),
        "no climb integral, firmer (climb kp 1.0, altitude->climb 0.25)": replace(
            own, climb=(1.0, 0.0, 0.0), altitude_to_climb=0.25
        ),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--turbulence", default="moderate")
    parser.add_argument("--episodes", type=int, default=16, help="episodes a block")
    args = parser.parse_args()
    flight = FlightOptions(task="altitude", aircraft="c172p", turbulence=args.turbulence).flight()
    own = gains_module.GAINS["c172p"]
    print(f"altitude on c172p, {args.turbulence} turbulence, blocks {BLOCKS} x {args.episodes}")
    print(f"{'gains':66s} {'success by block':>20s} {'all':>5s} {'error ft':>9s}")
    try:
        for name, gains in variants().items():
            gains_module.GAINS["c172p"] = gains
            rates, errors = [], []
            for block in BLOCKS:
                seeds = list(range(block, block + args.episodes))
                (row,), _ = evaluate(flight, {"controller": AgentSpec.controller()}, seeds)
                rates.append(row["success_rate"])
                errors += [e["steady_state_error"] for e in row["per_episode"]]
            cells = " / ".join(f"{100 * r:.0f}" for r in rates)
            print(f"{name:66s} {cells:>20s} {100 * np.mean(rates):4.0f}% {np.nanmean(errors):9.1f}")
    finally:
        gains_module.GAINS["c172p"] = own


if __name__ == "__main__":
    main()
