"""Where an agent step goes, between JSBSim's ``run()`` and the value ``env.step`` returns.

    PYTHONPATH=. python docs/experiments/step_profile.py [--calls 20000] [--rounds 5] [--json FILE]

Each part of a c172p altitude step at 10 Hz (12 JSBSim frames) is timed on its own, many calls
in a row, the median of ``--rounds`` rounds, with the cost of an empty call taken off:

- the physics: 12 ``FGFDMExec.run()`` on a second instance of the same model;
- the property I/O a bare loop does too (the four controls written, the catalogue read);
- the env's own parts: the action check, the world's bookkeeping around the I/O, the score
  (reward context, target, termination, reward), the observation, and what ``step`` itself
  adds. These are timed in the env with its JSBSim frames switched off (an empty substep
  range), so the state stays the one a reset flew into and the episode never ends;
- the training env's layers, outside in (``rl.envs.make_env``, as ``train ppo`` builds one,
  with and without the policy's memory): what each wrapper adds to a step.

The table is in docs/results/speed.md.
"""

from __future__ import annotations

import argparse
import functools
import json
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.envs.actions import controls
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.sim.simulation import Simulation


def per_call(fn: Callable[[], Any], calls: int, rounds: int) -> float:
    """µs a call of ``fn``: the median of ``rounds`` rounds of ``calls`` calls, less an empty
    call's cost."""

    def timed(f: Callable[[], Any]) -> float:
        t0 = time.perf_counter_ns()
        for _ in range(calls):
            f()
        return (time.perf_counter_ns() - t0) / calls / 1000

    def empty() -> None:
        pass

    return statistics.median(timed(fn) - timed(empty) for _ in range(rounds))


def frozen(env: Any) -> Any:
    """``env`` (an AircraftEnv, reset) with its JSBSim frames switched off and no end: every
    step reads the state a reset flew into."""
    world = env.world
    world.slots[0].sim._substep_range = range(0)
    world.max_steps = 10**12
    return env


def profile(calls: int, rounds: int) -> dict[str, float]:
    """µs a step of each part (the keys in the order of the table)."""
    flight = FlightSpec.solo("c172p", "altitude")
    physics = Simulation("c172p")
    physics.reset(flight.make_env().task.initial_conditions(np.random.default_rng(0)))
    run = physics.fdm.run

    def frames() -> None:
        for _ in range(12):
            run()

    env = flight.make_env()
    env.reset(seed=0)
    env = frozen(env)
    world, slot = env.world, env.world.slots[0]
    sim, task = slot.sim, slot.task
    action = np.array([0.0, 0.0, 0.0, 0.75], np.float32)
    ctrl = controls(action)
    parts: dict[str, float] = {}
    parts["JSBSim, 12 frames"] = per_call(frames, max(1, calls // 50), rounds)
    parts["controls written (4 nodes)"] = per_call(lambda: sim.apply(*ctrl), calls, rounds)
    parts["state read (26 nodes)"] = per_call(sim.read, calls, rounds)
    io = parts["controls written (4 nodes)"] + parts["state read (26 nodes)"]
    parts["action check"] = per_call(lambda: controls(action), calls, rounds)
    bookkeeping = per_call(lambda: world.step_physics((ctrl,)), calls, rounds)
    parts["world bookkeeping"] = bookkeeping - io
    parts["score (context, target, termination, reward)"] = per_call(world.score, calls, rounds)
    parts["observation"] = per_call(lambda: task.observe(slot.state, world.steps), calls, rounds)
    whole = per_call(lambda: env.step(action), calls, rounds)
    parts["env.step's own"] = whole - sum(
        v for k, v in parts.items() if k not in ("JSBSim, 12 frames",)
    )
    parts["env.step, physics off"] = whole
    for name, memory in (("training env", False), ("training env with memory", True)):
        for layer, cost in layers(flight, action, memory, calls, rounds):
            parts[f"{name}: {layer}"] = cost
    return parts


def layers(
    flight: FlightSpec, action: np.ndarray, memory: bool, calls: int, rounds: int
) -> list[tuple[str, float]]:
    """(wrapper, µs it adds to a step) for each layer of a training env, outermost first."""
    from gymfg_il.policies.memory import LoopMemoryRecipe
    from gymfg_il.rl.envs import make_env

    maker = None
    if memory:
        probe = flight.make_env()
        recipe = LoopMemoryRecipe.for_flight(flight.to_dict(), probe.observation_names)
        probe.close()
        maker = functools.partial(recipe.new, recipe.default)
    env = make_env(flight.to_dict(), [0.0] * 4, [1.0] * 4, 0.2, maker)
    env.reset(seed=0)
    frozen(env.unwrapped)
    costs, layer = [], env
    while True:
        costs.append(
            (type(layer).__name__, per_call(lambda lay=layer: lay.step(action), calls, rounds))
        )
        if not hasattr(layer, "env"):
            break
        layer = layer.env
    return [
        (name, cost - (costs[i + 1][1] if i + 1 < len(costs) else 0.0))
        for i, (name, cost) in enumerate(costs)
    ]


def _raw_rate(steps: int, queue: Any) -> None:
    """Steps/s of the bare loop (``benchmarks.physics.raw_loop``), put on ``queue``."""
    from benchmarks.physics import raw_loop

    run = raw_loop()
    run(steps // 10)  # warm
    t0 = time.perf_counter()
    run(steps)
    queue.put(steps / (time.perf_counter() - t0))


def core_scaling(steps: int, rounds: int) -> tuple[float, int]:
    """(the bare loop's steps/s in ``cores`` processes at once over one process's, cores):
    what the physics bound of the RL rows (cores x one bare loop) assumes is ``cores``."""
    import multiprocessing as mp
    import os

    cores = len(os.sched_getaffinity(0))
    ctx = mp.get_context("forkserver")

    def together(n: int) -> float:
        queue = ctx.Queue()
        procs = [ctx.Process(target=_raw_rate, args=(steps, queue)) for _ in range(n)]
        for proc in procs:
            proc.start()
        total = sum(queue.get() for _ in procs)
        for proc in procs:
            proc.join()
        return total

    ratios = [together(cores) / together(1) for _ in range(rounds)]
    return statistics.median(ratios), cores


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--calls", type=int, default=20000, help="calls a round")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--json", type=Path, help="write the parts to this JSON file")
    args = p.parse_args(argv)
    parts = profile(args.calls, args.rounds)
    physics = parts["JSBSim, 12 frames"]
    io = parts["controls written (4 nodes)"] + parts["state read (26 nodes)"]
    step = physics + parts["env.step, physics off"]
    print(f"{'part':<50} {'µs a step':>10} {'share':>7}")
    for name, cost in parts.items():
        share = (
            "" if name.startswith("training") or "physics off" in name else f"{cost / step:7.1%}"
        )
        print(f"{name:<50} {cost:10.2f} {share:>7}")
    print(
        f"\nbare loop (physics + I/O) {physics + io:.1f} µs, env.step {step:.1f} µs: "
        f"the bound env_step_vs_raw_jsbsim can reach is {(physics + io) / step:.3f}"
    )
    scaling, cores = core_scaling(3000, args.rounds)
    print(
        f"{cores} bare loops at once, each in a process of its own: {scaling:.2f}x one loop's "
        f"steps/s (the RL rows' physics bound counts {cores}x)"
    )
    parts["bare loops on every core over one"] = scaling
    if args.json:
        args.json.write_text(json.dumps(parts, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
