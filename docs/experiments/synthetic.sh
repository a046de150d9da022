#!/bin/bash
# 30 synthetic-pilot keyboard demonstrations of altitude -> train bc -> eval beside the pilot
# (docs/results/defaults.md, "From the synthetic pilot": seeds 0/600, 2000/3000, 4000/5000).
# Usage: bash docs/experiments/synthetic.sh [OUT] [SEED] [EVAL_SEED]
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/synthetic}
SEED=${2:-2000}
EVAL_SEED=${3:-$((SEED + 1000))}
python -m gymfg_il.collect manual --pilot synthetic --device keyboard --task altitude \
  --episodes 30 --seed "$SEED" --out "$OUT" --no-progress
python -m gymfg_il.train bc --dataset "$OUT/dataset" --out "$OUT/policy" --no-progress
python -m gymfg_il.eval --policy "$OUT/policy" --pilot synthetic --device keyboard \
  --episodes 16 --seed "$EVAL_SEED" --no-progress
