#!/bin/bash
# The "Other aircraft" table of docs/results/maneuvers.md: every maneuver's expert on the
# c172p, the f15 and the A320 with default flags, 16 held-out episodes each (the plans and
# gains were tuned on seeds 100-199), then one line per row: successes, crashes, the mean
# return and the worst episode's. About 3 minutes on one core.
# Usage: bash docs/experiments/maneuver_experts.sh [OUT] [SEED]   (the page: SEED 9100)
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/maneuver_experts}
SEED=${2:-9100}
mkdir -p "$OUT"
for AIRCRAFT in c172p f15 A320; do
  for TASK in turn climb-turn waypoints formation approach; do
    python -m gymfg_il.eval --task "$TASK" --aircraft "$AIRCRAFT" --episodes 16 --seed "$SEED" \
      --json "$OUT/$TASK-$AIRCRAFT.json" --no-progress
  done
done
python - "$OUT" <<'PY'
import json, pathlib, sys

print("| aircraft | maneuver | success | crashed | mean return | worst return | episode |")
print("|---|---|---|---|---|---|---|")
for aircraft in ("c172p", "f15", "A320"):
    for task in ("turn", "climb-turn", "waypoints", "formation", "approach"):
        row = json.loads((pathlib.Path(sys.argv[1]) / f"{task}-{aircraft}.json").read_text())
        row = row["rows"][0]
        episodes = row["per_episode"]
        won = sum(e["success"] for e in episodes)
        worst = min(e["total_return"] for e in episodes)
        print(
            f"| {aircraft} | {task} | {won} of {len(episodes)} | {row['terminated']} | "
            f"{row['mean_return']:.1f} | {worst:.1f} | {row['episode_time_s']:g} s |"
        )
PY
