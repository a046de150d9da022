"""How firmly a heading clone answers a small heading or roll error, against its autopilot:
the clone flies its own flight (``--turbulence`` to change the air) on a few seeds, and from
``--after`` seconds on (the hold, past the turn) every tenth step its aileron's slope is
measured by finite differences, one degree more heading error (target and error moved
together) and one degree more roll, and divided by the autopilot's unsaturated slopes there
(``heading_to_roll`` x the roll loop's gain, and the roll loop's gain). Prints the median
and the 10th and 90th percentiles of each ratio, and of the rudder's answer to that degree
of heading error (the autopilot's rudder sees only the sideslip: 0; a rudder that holds the
heading in gusts, docs/experiments/hold_gains.py, -0.02 to -0.05). Not a feature: the
diagnosis behind docs/results/memory.md ("Still-air demonstrations, flown in moderate
turbulence") and docs/results/rl.md.

    python docs/experiments/heading_gains.py POLICY [--turbulence moderate] [--seeds 7000 7004]
"""

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.policies.agent import PolicyAgent

LOW, HIGH = np.array([-1.0, -1.0, -1.0, 0.0]), np.ones(4)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("policy", type=Path, help="a heading policy's folder")
    parser.add_argument("--turbulence", default=None, help="the air (default: the policy's)")
    parser.add_argument("--seeds", type=int, nargs=2, default=(7000, 7004), help="first, end")
    parser.add_argument("--after", type=float, default=30.0, help="seconds before measuring")
    args = parser.parse_args()

    agent = PolicyAgent.load(args.policy)
    policy = agent.policy
    spec = json.loads((args.policy / "config.json").read_text())["spec"]
    if args.turbulence is not None:
        spec = {**spec, "turbulence": args.turbulence}
    env = FlightSpec.from_dict(spec).make_env()
    names = list(env.task.observation_names)
    error, target, roll = (
        names.index(n) for n in ("heading_deg_error", "heading_deg_target", "roll_deg")
    )
    expert = controller_for(
        env.task, env.aircraft.model, env.dt, env.aircraft.profile.cruise_throttle
    )
    heading_slope = expert.gains.heading_to_roll * expert.roll_pid.kp
    roll_slope = -expert.roll_pid.kp

    def controls(x: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            out = policy.action_norm.inverse(policy.forward(torch.as_tensor(x[None])))
        return out[0].numpy()

    ratios: dict[str, list[float]] = {"heading": [], "roll": []}
    rudder: list[float] = []
    start = int(args.after / env.dt)
    for seed in range(*args.seeds):
        obs, _ = env.reset(seed=seed)
        agent.reset()
        for step in range(10**6):
            action = agent.act(obs)
            if step >= start and step % 10 == 0:
                memory = agent._state[0] if agent._state is not None else None
                held = [] if memory is None else [pid.integral for pid in memory.pids]
                x = np.concatenate([obs, held]).astype(np.float32)
                base = controls(x)
                turned, rolled = x.copy(), x.copy()
                turned[[error, target]] += 1.0
                rolled[roll] += 1.0
                answer = controls(turned) - base
                ratios["heading"].append(answer[0] / heading_slope)
                ratios["roll"].append((controls(rolled)[0] - base[0]) / roll_slope)
                rudder.append(answer[2])
            obs, _, terminated, truncated, _ = env.step(np.clip(action, LOW, HIGH))
            if terminated or truncated:
                break
    env.close()
    for what, values in ratios.items():
        p10, p50, p90 = np.percentile(values, [10, 50, 90])
        print(f"clone / autopilot, {what} error: median {p50:.2f} (p10 {p10:.2f}, p90 {p90:.2f})")
    p10, p50, p90 = np.percentile(rudder, [10, 50, 90])
    print(f"rudder per degree of heading error: median {p50:+.4f} (p10 {p10:+.4f}, p90 {p90:+.4f})")


if __name__ == "__main__":
    main()
