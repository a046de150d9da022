#!/bin/bash
# A vision policy against the state policy on roll (or TASK), c172p, default flags (docs/results/vision.md).
# Usage: [TASK=heading] bash docs/experiments/vision.sh OUT [DEMOS] [COLLECT_SEED] [EVAL_SEED ...]
# Prints each eval's table and the vision policy's share of the state policy's return.
set -euo pipefail
export HF_HUB_OFFLINE=1
OUT=${1:-runs/experiments/vision}
DEMOS=${2:-40}
TASK=${TASK:-roll}
SEED=${3:-1000}
shift 3 || true
EVAL_SEEDS=${*:-9000}
python -m gymfg_il.collect autopilot --task "$TASK" --episodes "$DEMOS" --seed "$SEED" --images front \
  --workers 2 --out "$OUT/demos" --no-progress > /dev/null
python -m gymfg_il.train bc --dataset "$OUT/demos/dataset" --out "$OUT/state" --no-progress | grep "^trained"
python -m gymfg_il.train bc --dataset "$OUT/demos/dataset" --policy vision --out "$OUT/vision" \
  --no-progress | grep "^trained"
for e in $EVAL_SEEDS; do
  python -m gymfg_il.eval --policy "$OUT/state" "$OUT/vision" --episodes 16 --seed "$e" --workers 2 \
    --no-progress --json "$OUT/eval-$e.json" | grep -E "^ *(controller|policy)"
  python - "$OUT/eval-$e.json" <<'PY'
import json, sys
rows = {r["agent"]: r for r in json.load(open(sys.argv[1]))["rows"]}
state, vision = rows["policy:state"], rows["policy:vision"]
worst = min(e["total_return"] for e in vision["per_episode"])
print(f"vision / state: return {vision['mean_return'] / state['mean_return']:.1%}, "
      f"success {vision['success_rate']:.0%} vs {state['success_rate']:.0%}, "
      f"crashed {vision['terminated']}, worst episode {worst:.1f} "
      f"(state's worst {min(e["total_return"] for e in state["per_episode"]):.1f})")
PY
done
