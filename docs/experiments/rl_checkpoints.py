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
select_episodes seeds (``train ppo``'s choice), on the CHECK seeds, the best held out (the
ceiling no rule can pass), and the mean of the weights of the actors from --average-from of
the run on (what ``train ppo --keep average`` kept, an option since removed, flown the same
way). The results: docs/experiments/rl-sessions.md (tenth and eleventh sessions).
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from pathlib import Path
from typing import Any

import torch
from safetensors.torch import load_file, save_file

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.evaluation.metrics import score_episode
from gymfg_il.evaluation.runner import evaluate
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.workers import Workers

BLOCKS = (9300, 9400, 9500)


def mean_weights(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """The mean of several state dicts of one network (torch tensors), in float64 and cast
    back, so that what is the same in all (the normalisations) stays exactly as it is."""
    return {
        k: torch.stack([w[k].double() for w in parts]).mean(0).to(v.dtype)
        if v.is_floating_point()
        else v
        for k, v in parts[-1].items()
    }


def averaged(run: Path, steps: list[int], folder: Path) -> Path:
    """A policy in ``folder`` whose weights are the mean of the checkpoints of ``steps``, as
    ``train ppo --keep average`` computed it before it was removed (``mean_weights``)."""
    parts = [load_file(str(run / "checkpoints" / f"step-{s}" / "model.safetensors")) for s in steps]
    folder.mkdir(parents=True)
    shutil.copy(run / "checkpoints" / f"step-{steps[-1]}" / "config.json", folder / "config.json")
    save_file(mean_weights(parts), str(folder / "model.safetensors"))
    return folder


Row = tuple[float, float, list[float]]  # success on the check seeds, held out, its blocks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path, help="a train ppo folder saved with --checkpoints")
    parser.add_argument("--check-seed", type=int, default=8000, help="first fresh seed")
    parser.add_argument("--check", type=int, default=64, help="fresh episodes a checkpoint")
    parser.add_argument(
        "--average-from", type=float, default=0.5, help="share of the run the mean starts at"
    )
    args = parser.parse_args()
    rl = json.loads((args.run / "curve.json").read_text())
    own = {p["step"]: p for p in rl["curve"]}
    late = [s for s in sorted(own) if s > 0 and s >= args.average_from * rl["steps"]]
    held_seeds = [b + i for b in BLOCKS for i in range(16)]
    check_seeds = list(range(args.check_seed, args.check_seed + args.check))

    def fly(path: Path, pool: Workers) -> Row:
        spec = FlightSpec.from_dict(json.loads((path / "config.json").read_text())["spec"])
        _, traces = evaluate(spec, {"p": AgentSpec.policy(path)}, check_seeds + held_seeds, pool)
        ok = [score_episode(t).success for t in traces["p"]]
        check, held = ok[: len(check_seeds)], ok[len(check_seeds) :]
        blocks = [100 * sum(held[16 * i : 16 * i + 16]) / 16 for i in range(len(BLOCKS))]
        return sum(check) / len(check), sum(held) / len(held), blocks

    def shown(row: Row) -> str:
        return f"{100 * row[0]:5.0f}%  {100 * row[1]:5.0f}% " + " / ".join(
            f"{b:.0f}" for b in row[2]
        )

    rows: dict[int, Row] = {}
    print("step       own 16  chosen on   check  held out (blocks)")
    with Workers(2) as pool, tempfile.TemporaryDirectory(prefix="rl-mean-") as scratch:
        for step in sorted(own):
            rows[step] = fly(args.run / "checkpoints" / f"step-{step}", pool)
            p = own[step]
            print(
                f"{step:>9,}  {100 * p['success']:5.0f}%  {100 * p['select_success']:5.0f}% "
                f"({p['chosen_on']})  " + shown(rows[step]),
                flush=True,
            )
        mean = fly(averaged(args.run, late, Path(scratch) / "mean"), pool)
    print(f"mean of the {len(late)} actors of steps {late[0]:,}..{late[-1]:,}: " + shown(mean))
    first = sorted(own)  # ties go to the earlier actor, as train ppo's choice does
    kept = {
        "the curve's 16 seeds": max(
            first, key=lambda s: (own[s]["success"], own[s]["mean_return"])
        ),
        f"the {args.check} fresh seeds": max(first, key=lambda s: rows[s][0]),
        "the held-out blocks (the ceiling)": max(first, key=lambda s: rows[s][1]),
    }
    if not rl["kept"].get("averaged"):  # else train ppo kept the mean (--keep average)
        kept[f"train ppo's choice ({rl['kept']['chosen_on']} seeds)"] = rl["kept"]["step"]
    print("\nheld out, the actor each rule keeps:")
    for rule, step in kept.items():
        blocks = " / ".join(f"{b:.0f}" for b in rows[step][2])
        print(f"  best on {rule:38s} step {step:>9,}: {100 * rows[step][1]:.0f}% ({blocks})")
    blocks = " / ".join(f"{b:.0f}" for b in mean[2])
    print(f"  the mean of the late actors (--keep average){'':9s}: {100 * mean[1]:.0f}% ({blocks})")


if __name__ == "__main__":
    main()
