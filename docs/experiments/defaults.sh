#!/bin/bash
# Default flags, 40 autopilot demonstrations -> train bc -> eval on held-out seeds (README,
# "Defaults that fly"). Usage: bash docs/experiments/defaults.sh [OUT] [TASK-AIRCRAFT ...]
set -euo pipefail
export HF_HUB_OFFLINE=1
OUT=${1:-runs/experiments/defaults}
shift || true
COMBOS=${*:-altitude-c172p roll-c172p heading-c172p altitude-f15 roll-f15 heading-f15}
for combo in $COMBOS; do
  task=${combo%-*} aircraft=${combo#*-} d=$OUT/$combo
  python -m gymfg_il.collect autopilot --task "$task" --aircraft "$aircraft" --episodes 40 \
    --seed 1000 --workers 2 --out "$d" --no-progress > /dev/null
  python -m gymfg_il.train bc --dataset "$d/dataset" --out "$d/policy" --no-progress | grep "^trained"
  python -m gymfg_il.eval --policy "$d/policy" --episodes "${EPISODES:-16}" --seed 9000 \
    --workers 2 --no-progress | grep "/ controller"
done
