"""Fingerprints of what GymFG-IL flies and learns, to hold a refactor to "nothing changes".

    python docs/experiments/fingerprints.py [--out FILE.json] [--against FILE.json]

Runs each command line a user runs, on fixed seeds, and hashes what it makes: the frames
and episode records of the datasets `collect autopilot`, `collect manual --pilot synthetic`
and `collect manual --pilot synthetic --device mouse` write (wall-clock columns and log
names left out), the weights of `train bc` and `train ppo` policies (and PPO's curve, the
actor at each evaluation), `eval`'s JSON rows and a controller's trajectories through the
rollout loop. Prints one line per item; with
``--against`` the earlier run's file, says which differ and exits 1 if any does. About 2
minutes on 2 cores. PPO repeats bit for bit only with the same number of envs on the same
install, so it runs with --envs 2.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "datasets/sample-altitude-c172p/dataset"
# episode records that differ between two runs of the same thing: when and into which file
UNSTABLE = {"gymfg/wall_start", "gymfg/log", "gymfg/rate_hz", "gymfg/jitter_ms"}


def run(*argv: str) -> None:
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}
    done = subprocess.run([sys.executable, "-m", *argv], capture_output=True, text=True, env=env)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed:\n{done.stderr[-2000:]}")


def digest(*parts: object) -> str:
    h = hashlib.blake2b(digest_size=12)
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(str(part.dtype).encode() + str(part.shape).encode())
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(json.dumps(part, sort_keys=True, default=str).encode())
    return h.hexdigest()


def dataset(root: Path) -> str:
    """The frames and the stable episode records of the dataset at ``root``."""
    import pyarrow.parquet as pq

    frames = []
    for path in sorted((root / "data").rglob("*.parquet")):
        table = pq.read_table(path)
        keep = [c for c in table.column_names if c != "wall_time_s"]
        frames += [np.array(table[c].to_pylist(), dtype=np.float64) for c in keep]
    records = []
    for path in sorted((root / "meta" / "episodes").rglob("*.parquet")):
        table = pq.read_table(path)
        names = [c for c in table.column_names if c.startswith("gymfg/") and c not in UNSTABLE]
        records.append(table.select(names).to_pydict())
    return digest(*frames, records)


def weights(folder: Path) -> str:
    from safetensors.numpy import load_file

    tensors = load_file(folder / "model.safetensors")
    return digest(*(tensors[k] for k in sorted(tensors)))


def trajectories() -> str:
    """Each task's controller through the rollout loop, two seeds each."""
    from gymfg_il.envs.options import FlightOptions
    from gymfg_il.rollout import AgentSpec, Rollout

    parts = []
    for task in ("altitude", "turn", "approach"):
        env = FlightOptions(task=task).flight().make_env()
        pilot = AgentSpec.controller().make(env)
        for seed in (11, 12):
            solo = Rollout(env, [pilot]).episode(seed=seed).solo
            parts += [solo.observations, solo.actions, solo.rewards]
        env.close()
    return digest(*parts)


def fingerprints(work: Path) -> dict[str, str]:
    out: dict[str, str] = {"trajectories": trajectories()}
    auto = work / "auto"
    run(
        "gymfg_il.collect",
        "autopilot",
        "--task",
        "turn",
        "--episodes",
        "3",
        "--episode-time",
        "20",
        "--seed",
        "7000",
        "--noise",
        "0.1",  # the turn's own is 0.2 since 2026-11-29: fingerprints stay comparable
        "--out",
        str(auto),
        "--no-progress",
    )
    out["collect autopilot"] = dataset(auto / "dataset")
    for device in ("keyboard", "mouse"):
        folder = work / f"manual-{device}"
        run(
            "gymfg_il.collect",
            "manual",
            "--pilot",
            "synthetic",
            "--device",
            device,
            "--task",
            "altitude",
            "--episodes",
            "2",
            "--episode-time",
            "30",
            "--seed",
            "7100",
            "--out",
            str(folder),
            "--no-progress",
        )
        out[f"collect manual synthetic {device}"] = dataset(folder / "dataset")
    bc = work / "bc"
    run(
        "gymfg_il.train",
        "bc",
        "--dataset",
        str(SAMPLE),
        "--epochs",
        "3",
        "--out",
        str(bc),
        "--no-progress",
    )
    out["train bc"] = weights(bc)
    rows = work / "eval.json"
    run(
        "gymfg_il.eval",
        "--policy",
        str(bc),
        "--episodes",
        "4",
        "--seed",
        "9000",
        "--json",
        str(rows),
        "--no-progress",
    )
    figures = json.loads(rows.read_text())
    for row in figures if isinstance(figures, list) else [figures]:
        if isinstance(row, dict):
            row.pop("seconds", None)
    out["eval"] = digest(figures)
    ppo = work / "ppo"
    run(
        "gymfg_il.train",
        "ppo",
        "--init",
        str(bc),
        "--steps",
        "8192",
        "--envs",
        "2",
        "--eval-every",
        "4096",
        "--eval-episodes",
        "4",
        "--select-episodes",
        "4",
        "--seed",
        "5",
        "--out",
        str(ppo),
        "--no-progress",
    )
    curve = json.loads((ppo / "curve.json").read_text())["curve"]
    for point in curve:
        point.pop("wall_s", None)
    out["train ppo"] = digest(weights(ppo), curve)  # the curve: the actor at each evaluation
    return out  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, help="write the fingerprints as JSON here")
    parser.add_argument("--against", type=Path, help="an earlier run's JSON to compare with")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        found = fingerprints(Path(tmp))
    earlier = json.loads(args.against.read_text()) if args.against else {}
    for name, value in found.items():
        said = "" if not earlier else "  same" if earlier.get(name) == value else "  DIFFERS"
        print(f"{name:36} {value}{said}")
    if args.out:
        args.out.write_text(json.dumps(found, indent=1) + "\n")
    return int(any(earlier.get(k) != v for k, v in found.items()) if earlier else 0)


if __name__ == "__main__":
    sys.exit(main())
