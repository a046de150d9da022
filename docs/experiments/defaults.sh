#!/bin/bash
# Default flags, 40 autopilot demonstrations -> train bc -> eval on held-out seeds (docs/results/defaults.md,
# "The target tasks"). Usage: bash docs/experiments/defaults.sh [OUT] [TASK-AIRCRAFT ...]
# Environment: DEMOS (40), COLLECT_SEED (1000), EPISODES (16), EVAL_SEED (9000; the results page's
# 8-episode rows: 9100),
# COLLECT (extra collect flags, e.g. "--turbulence moderate"), EVAL (extra eval flags, e.g.
# "--turbulence moderate" for the turbulence rows, with EPISODES=8 EVAL_SEED=9200).
set -euo pipefail
export HF_HUB_OFFLINE=1
OUT=${1:-runs/experiments/defaults}
shift || true
COMBOS=${*:-altitude-c172p roll-c172p heading-c172p altitude-f15 roll-f15 heading-f15}
for combo in $COMBOS; do
  task=${combo%-*} aircraft=${combo#*-} d=$OUT/$combo
  # shellcheck disable=SC2086
  python -m gymfg_il.collect autopilot --task "$task" --aircraft "$aircraft" \
    --episodes "${DEMOS:-40}" --seed "${COLLECT_SEED:-1000}" --workers 2 --out "$d" --no-progress ${COLLECT:-} > /dev/null
  python -m gymfg_il.train bc --dataset "$d/dataset" --out "$d/policy" --no-progress | grep "^trained"
  # shellcheck disable=SC2086
  python -m gymfg_il.eval --policy "$d/policy" --episodes "${EPISODES:-16}" \
    --seed "${EVAL_SEED:-9000}" --workers 2 --no-progress ${EVAL:-} | grep -E "^ *controller|/ controller"
done
