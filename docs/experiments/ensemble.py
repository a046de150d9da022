"""A probe for a proposal, not a feature: several clones of the same demonstrations (``train
bc --seed 0`` to ``4``) flown as one, the mean of their actions, on held-out seeds. Each clone
keeps its own memory (``PolicyAgent``); the flight is the first clone's. Prints the failures
and the success count; each clone alone: ``python -m gymfg_il.eval --policy ...``.

    python docs/experiments/ensemble.py POLICY [POLICY ...] [--seed 7500] [--episodes 32]

Measured (the turn from five; docs/results/memory.md): from seed 1100, the five clones alone 97
/ 100 / 100 / 100 / 97 %, two crashes on 7526, their mean 32 of 32; from seed 900, where every
clone fails 7412 (one crashes), their mean crashes on it: the seed's variance averages out,
a gap in the five demonstrations does not.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.evaluation.metrics import score_episode
from gymfg_il.evaluation.trace import trace_of
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.rollout import Rollout


class MeanAction:
    """The mean of the clones' actions; every clone steps on every observation."""

    def __init__(self, agents: list[PolicyAgent]) -> None:
        self.agents = agents

    def reset(self, seed: int | None = None) -> None:
        for agent in self.agents:
            agent.reset(seed)

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        return np.mean([agent.act(observation) for agent in self.agents], axis=0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("policies", type=Path, nargs="+", help="clones' folders")
    parser.add_argument("--seed", type=int, default=7500, help="first held-out seed")
    parser.add_argument("--episodes", type=int, default=32)
    args = parser.parse_args()
    spec = json.loads((args.policies[0] / "config.json").read_text())["spec"]
    env = FlightSpec.from_dict(spec).make_env()
    agents = [PolicyAgent.load(path) for path in args.policies]
    for agent in agents:
        agent.check_observation(env.task.observation_names)
    succeeded = crashed = 0
    for seed in range(args.seed, args.seed + args.episodes):
        score = score_episode(trace_of(Rollout(env, [MeanAction(agents)]).episode(seed)))
        succeeded += score.success
        crashed += score.terminated
        if not score.success:
            print(f"seed {seed}: {score.detail}", flush=True)
    env.close()
    flown = f"{succeeded} of {args.episodes} succeeded, {crashed} crashed"
    print(f"mean of {len(agents)} clones: {flown}")


if __name__ == "__main__":
    main()
