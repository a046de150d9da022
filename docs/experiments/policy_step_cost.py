"""What one step of flight costs a policy: ``PolicyAgent.act`` for the MLP without memory,
the MLP with the vertical loops' memory (``--memory vertical``, the altitude task's default;
its loop integrals updated once per step) and the default GRU (its hidden state carried: one
GRU step per call, whatever the step), on one episode of the bundled sample's observations,
one torch thread, untrained weights (a step costs the same). Paired rounds in alternating
order, so a busy machine slows all alike; prints the median step over all rounds, the range
of the rounds' medians, the GRU's first and last 100 steps of the episodes, and the median
of the rounds' ratios to the MLP. Not a feature: a measurement behind docs/results/memory.md
and docs/results/defaults.md ("Why a GRU epoch is slow").

    python docs/experiments/policy_step_cost.py [ROUNDS] [STEPS]
"""

import statistics
import sys
import time
from pathlib import Path

import torch

from gymfg_il.learning.data import load_frames
from gymfg_il.learning.memory import remembered
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration import DatasetInfo
from gymfg_il.policies.configuration_gru import GRUConfig
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.factory import make_policy

ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 20
STEPS = int(sys.argv[2]) if len(sys.argv) > 2 else 900
SAMPLE = Path(__file__).resolve().parents[2] / "datasets/sample-altitude-c172p/dataset"

torch.set_num_threads(1)
frames = load_frames(SAMPLE)
episode = frames.obs[frames.episode == frames.episode[0]][:STEPS]
meta = {"observation_names": frames.observation_names}
CONFIGS = {
    "mlp": MLPConfig(memory="none"),
    "mlp+memory": MLPConfig(memory="vertical"),
    "gru": GRUConfig(),
}
agents = {}
for name, config in CONFIGS.items():
    extended = remembered(frames, config)  # the memory's columns and statistics, if any
    info = DatasetInfo(extended.observation_names, frames.fps, frames.flight()[0])
    completed = config.for_data(info)
    module = make_policy(completed, extended.obs_stats, frames.action_stats).eval()
    agents[name] = PolicyAgent(module, meta)


def one_episode(agent: PolicyAgent) -> list[float]:
    """Seconds of each ``act`` over the episode, from a fresh state."""
    agent.reset()
    times = []
    for obs in episode:
        start = time.perf_counter()
        agent.act(obs)
        times.append(time.perf_counter() - start)
    return times


for agent in agents.values():
    one_episode(agent)  # warm up
steps: dict[str, list[float]] = {name: [] for name in agents}
medians: dict[str, list[float]] = {name: [] for name in agents}
for r in range(ROUNDS):
    for name in list(agents)[:: 1 if r % 2 == 0 else -1]:
        times = one_episode(agents[name])
        steps[name] += times
        medians[name].append(statistics.median(times))
print(f"{ROUNDS} rounds of {len(episode)} steps, torch {torch.__version__}, 1 thread")
for name in CONFIGS:
    low, high = min(medians[name]) * 1e6, max(medians[name]) * 1e6
    print(
        f"{name}: median step {statistics.median(steps[name]) * 1e6:.1f} us "
        f"(rounds {low:.1f}-{high:.1f} us)"
    )
n = len(episode)
early = [t for i, t in enumerate(steps["gru"]) if i % n < 100]
late = [t for i, t in enumerate(steps["gru"]) if i % n >= n - 100]
print(
    f"gru, first and last 100 steps of the episodes: {statistics.median(early) * 1e6:.1f} "
    f"and {statistics.median(late) * 1e6:.1f} us (the same work at every step)"
)
for name in ("mlp+memory", "gru"):
    ratios = [g / m for g, m in zip(medians[name], medians["mlp"], strict=True)]
    low, high = min(ratios), max(ratios)
    print(f"{name} / mlp: {statistics.median(ratios):.2f} (rounds {low:.2f}-{high:.2f})")
