#!/bin/bash
# 30 synthetic-pilot keyboard demonstrations of altitude -> train bc -> eval beside the pilot
# (README, "Defaults that fly"). Usage: bash docs/experiments/synthetic.sh [OUT] [SEED]
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/synthetic}
SEED=${2:-2000}
python -m gymfg_il.collect manual --pilot synthetic --device keyboard --task altitude \
  --episodes 30 --seed "$SEED" --out "$OUT" --no-progress
python -m gymfg_il.train bc --dataset "$OUT/dataset" --out "$OUT/policy" --no-progress
python -m gymfg_il.eval --policy "$OUT/policy" --pilot synthetic --device keyboard \
  --episodes 16 --seed $((SEED + 1000)) --no-progress
