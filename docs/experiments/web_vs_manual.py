"""BC from web demonstrations against BC from the same pilot's `collect manual` ones.

Eight headless web pilots (the display-bound synthetic pilot, ``gymfg_il.web.headless``) fly
EPISODES demonstrations between them through a real ``collect web`` server, in real time; the
same pilot flies the same seeds headless at this machine (``collect manual --pilot
synthetic``). ``train bc`` (default flags) learns from each dataset, and ``eval`` flies both
policies beside the pilot's controller on held-out seeds. Prints how many web episodes match
their manual twins step for step, and the two policies' success and return.

    python docs/experiments/web_vs_manual.py OUT [--task altitude] [--episodes 30]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np

PILOTS = 8
ENV = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy", "PYTHONUNBUFFERED": "1"}


def run(*args: str) -> str:
    done = subprocess.run([sys.executable, *args], env=ENV, capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(f"{' '.join(args)} failed:\n{done.stderr[-3000:]}")
    return done.stdout


def web(out: Path, task: str, seed: int, shares: list[int]) -> None:
    from gymfg_il.web.headless import fly

    proc = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.collect", "web", "--out", str(out), "--port", "0",
         "--pilots", str(PILOTS), "--task", task, "--seed", str(seed)],
        stdout=subprocess.PIPE, text=True, env=ENV,
    )  # fmt: skip
    assert proc.stdout is not None
    url, tokens = "", []
    for line in proc.stdout:
        if m := re.search(r"at (http://\S+?)/ ", line):
            url = m.group(1).replace("http://", "ws://") + "/ws"
        if m := re.search(r"#invite=(\S+)$", line):
            tokens.append(m.group(1))
        if "waiting for pilots" in line:
            break

    async def everyone() -> list:  # (fly_many, with each pilot's own share of episodes)
        ready = asyncio.Barrier(len(tokens))
        flights = (fly(url, t, n, ready=ready) for t, n in zip(tokens, shares, strict=True))
        return await asyncio.gather(*flights)

    try:
        flown = asyncio.run(everyone())
    finally:
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=300)
    print("web: saved", [f.saved for f in flown])


def manual(out: Path, task: str, seed: int, shares: list[int]) -> None:
    for k, n in enumerate(shares):
        if n:
            run("-m", "gymfg_il.collect", "manual", "--pilot", "synthetic", "--task", task,
                "--seed", str(seed + 10_000 * k), "--episodes", str(n), "--out", str(out),
                "--no-progress")  # fmt: skip


def twins(a: Path, b: Path) -> tuple[int, int]:
    """Web episodes whose actions equal their manual twin's (same seed), of all."""
    from gymfg_il.recording.reader import read_log

    def by_seed(folder: Path) -> dict[int, np.ndarray]:
        return {
            e.start["seed"]: e.steps["ego"].label
            for log in sorted((folder / "logs").glob("*.mcap"))
            for e in read_log(log).complete_episodes
        }

    here, there = by_seed(a), by_seed(b)
    same = sum(np.array_equal(v, there.get(s)) for s, v in here.items())
    return same, len(here)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("out", type=Path)
    p.add_argument("--task", default="altitude")
    p.add_argument("--episodes", type=int, default=30)
    p.add_argument("--seed", type=int, default=2000, help="the first pilot's first seed")
    p.add_argument("--eval-seed", type=int, default=7000)
    p.add_argument("--eval-episodes", type=int, default=16)
    args = p.parse_args()
    shares = [args.episodes // PILOTS + (k < args.episodes % PILOTS) for k in range(PILOTS)]
    web(args.out / "web", args.task, args.seed, shares)
    manual(args.out / "manual", args.task, args.seed, shares)
    same, total = twins(args.out / "web", args.out / "manual")
    print(f"web episodes equal to their manual twins, step for step: {same} of {total}")
    for name in ("web", "manual"):
        run("-m", "gymfg_il.train", "bc", "--dataset", str(args.out / name / "dataset"),
            "--out", str(args.out / f"{name}-bc"), "--no-progress")  # fmt: skip
    out = run("-m", "gymfg_il.eval", "--policy", str(args.out / "web-bc"),
              "--policy", str(args.out / "manual-bc"), "--episodes", str(args.eval_episodes),
              "--seed", str(args.eval_seed), "--json", str(args.out / "eval.json"),
              "--no-progress")  # fmt: skip
    print(out)
    rows = json.loads((args.out / "eval.json").read_text())["rows"]
    by = {r["agent"]: {e["seed"]: e["total_return"] for e in r["per_episode"]} for r in rows}
    w, m = by["policy:web-bc"], by["policy:manual-bc"]
    per_seed = [w[s] / m[s] for s in w]
    ratio = sum(w.values()) / sum(m.values())
    print(
        f"BC from web / BC from manual demonstrations: return {ratio:.4f} "
        f"(per seed {min(per_seed):.4f} .. {max(per_seed):.4f})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
