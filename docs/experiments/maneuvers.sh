#!/bin/bash
# The maneuvers tables of docs/results/maneuvers.md: for each maneuver, 50 expert demonstrations
# (default flags) -> an MLP and a chunking policy -> eval beside the expert on held-out seeds;
# then 50 synthetic-pilot keyboard demonstrations of turn and waypoints -> an MLP -> eval
# beside the pilot. About 40 minutes on two cores.
# Usage: bash docs/experiments/maneuvers.sh [OUT] [EVAL_SEED] [AIRCRAFT] [SEED]
# Environment: COLLECT (extra collect flags, e.g. "--noise 0.05" for the page's 0.05 rows).
# (the page's figures: EVAL_SEED 5000, SEED 0 for the expert's demonstrations; the pilot's
# are always collected from 2000 and evaluated from EVAL_SEED + 1000)
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/maneuvers}
EVAL_SEED=${2:-5000}
AIRCRAFT=${3:-c172p}
SEED=${4:-0}
for TASK in turn climb-turn waypoints formation approach; do
  D="$OUT/$TASK-$AIRCRAFT"
  # shellcheck disable=SC2086
  [ -d "$D/dataset" ] || python -m gymfg_il.collect autopilot --task "$TASK" --aircraft "$AIRCRAFT" \
    --episodes 50 --seed "$SEED" --out "$D" --no-progress ${COLLECT:-}
  for POLICY in mlp chunk; do
    [ -f "$D-$POLICY/config.json" ] || python -m gymfg_il.train bc --dataset "$D/dataset" \
      --policy "$POLICY" --out "$D-$POLICY" --no-progress
  done
  python -m gymfg_il.eval --policy "$D-mlp" --policy "$D-chunk" --episodes 16 \
    --seed "$EVAL_SEED" --plots "$OUT/plots" --json "$D.eval.json" --no-progress
done
for TASK in turn waypoints; do
  D="$OUT/pilot-$TASK-$AIRCRAFT"
  [ -d "$D/dataset" ] || python -m gymfg_il.collect manual --pilot synthetic --device keyboard \
    --task "$TASK" --aircraft "$AIRCRAFT" --episodes 50 --seed 2000 --out "$D" --no-progress
  [ -f "$D-mlp/config.json" ] || python -m gymfg_il.train bc --dataset "$D/dataset" \
    --out "$D-mlp" --no-progress
  [ -f "$D-chunk20/config.json" ] || python -m gymfg_il.train bc --dataset "$D/dataset" \
    --policy chunk --epochs 20 --out "$D-chunk20" --no-progress
  python -m gymfg_il.eval --policy "$D-mlp" --policy "$D-chunk20" --pilot synthetic \
    --device keyboard --episodes 16 --seed $((EVAL_SEED + 1000)) --json "$D.eval.json" \
    --no-progress
done
