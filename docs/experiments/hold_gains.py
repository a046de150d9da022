"""What the c172p's altitude and heading holds need in moderate turbulence: the controller
flown with one loop's gains changed, on the held-out blocks the RL results report.

    python docs/experiments/hold_gains.py [--task altitude|heading] [--turbulence moderate]
        [--episodes 16] [--blocks 9300 9400 9500]

Gain sets of the controller (``controllers.gains``), each on every block: for the altitude,
its own; its own without the climb loop's integral (the altitude loop then maps the state to
the elevator with no memory, as a cloned MLP does); and that memoryless loop with a firmer
altitude-to-climb gain and climb gain. For the heading, its own, its heading-to-bank gain at
0.75, 1.5 and 2 times, its roll loop at 1.5 and 2 times, and its own with the rudder holding
the heading too (the autopilot's rudder only cancels the sideslip): a rudder term on the
heading error (per degree, the error clipped at 5 deg), on the yaw rate, or both. Prints
success per block and the mean error over the last 10 s (the verdict's; tolerance 50 ft,
3 deg). Each set flies in this process (one worker), its gains set in ``GAINS`` for the c172p
while it flies, the rudder term added to ``Autopilot._rudder`` while it flies. The results:
docs/results/rl.md.
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterator
from dataclasses import replace

import numpy as np

from gymfg_il.controllers import gains as gains_module
from gymfg_il.controllers.autopilot import Autopilot
from gymfg_il.envs.options import FlightOptions
from gymfg_il.evaluation.runner import evaluate
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.units import RAD_TO_DEG, wrap_180

# the rudder's heading terms: (rudder per degree of heading error, per degree/s of yaw rate)
RUDDER = {
    "own + rudder 0.02 per deg of heading error": (0.02, 0.0),
    "own + rudder 0.05 per deg of heading error": (0.05, 0.0),
    "own + yaw damper 0.05 per deg/s": (0.0, 0.05),
    "own + rudder 0.03 per deg, yaw damper 0.03": (0.03, 0.03),
}


@contextlib.contextmanager
def rudder_holding_heading(per_deg: float, per_deg_s: float) -> Iterator[None]:
    """The autopilot's rudder, plus ``-per_deg`` x the heading error (clipped at 5 deg) and
    ``+per_deg_s`` x the yaw rate, on the heading loop (positive rudder yaws left here, a
    positive yaw rate is the nose going right: the second term damps it)."""
    own = Autopilot._rudder

    def rudder(self: Autopilot, obs: list[float]) -> float:
        base = own(self, obs)
        i, t = self.index, self.targets
        if t.lateral != "heading" or t.sideslip_source is not None:
            return base
        target = self._value(obs, t.lateral_source, "heading_deg", "lateral")
        err = max(-5.0, min(5.0, wrap_180(target - obs[i["heading_deg"]])))
        extra = -per_deg * err + per_deg_s * obs[i["r_rad_s"]] * RAD_TO_DEG
        return max(-1.0, min(1.0, base + extra))

    Autopilot._rudder = rudder  # type: ignore[method-assign]
    try:
        yield
    finally:
        Autopilot._rudder = own  # type: ignore[method-assign]


def variants(task: str) -> dict[str, gains_module.Gains]:
    own = gains_module.GAINS["c172p"]
    if task == "heading":
        sets = {f"own (heading->bank {own.heading_to_roll}, roll {own.roll})": own}
        for k in (0.75, 1.5, 2.0):
            sets[f"heading->bank x{k:g}"] = replace(own, heading_to_roll=own.heading_to_roll * k)
        for k in (1.5, 2.0):
            roll = (own.roll[0] * k, own.roll[1] * k, own.roll[2] * k)
            sets[f"roll loop x{k:g}"] = replace(own, roll=roll)
        return sets
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
    parser.add_argument("--task", choices=("altitude", "heading"), default="altitude")
    parser.add_argument("--turbulence", default="moderate")
    parser.add_argument("--episodes", type=int, default=16, help="episodes a block")
    parser.add_argument("--blocks", type=int, nargs="+", default=[9300, 9400, 9500])
    args = parser.parse_args()
    flight = FlightOptions(task=args.task, aircraft="c172p", turbulence=args.turbulence).flight()
    own = gains_module.GAINS["c172p"]
    unit = "deg" if args.task == "heading" else "ft"
    air = f"{args.turbulence} turbulence"
    print(f"{args.task} on c172p, {air}, blocks {args.blocks} x {args.episodes}")
    print(f"{'gains':66s} {'success by block':>26s} {'all':>5s} {'error ' + unit:>9s}")
    sets = [(name, gains, (0.0, 0.0)) for name, gains in variants(args.task).items()]
    if args.task == "heading":
        sets += [(name, own, terms) for name, terms in RUDDER.items()]
    try:
        for name, gains, terms in sets:
            gains_module.GAINS["c172p"] = gains
            rates, errors = [], []
            with rudder_holding_heading(*terms):
                for block in args.blocks:
                    seeds = list(range(block, block + args.episodes))
                    (row,), _ = evaluate(flight, {"controller": AgentSpec.controller()}, seeds)
                    rates.append(row["success_rate"])
                    errors += [e["steady_state_error"] for e in row["per_episode"]]
            cells = " / ".join(f"{100 * r:.0f}" for r in rates)
            print(f"{name:66s} {cells:>26s} {100 * np.mean(rates):4.0f}% {np.nanmean(errors):9.2f}")
    finally:
        gains_module.GAINS["c172p"] = own


if __name__ == "__main__":
    main()
