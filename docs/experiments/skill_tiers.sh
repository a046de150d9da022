#!/bin/bash
# Pilots of mixed skill (robomimic's multi-human study, for flight; docs/results/skill_tiers.md).
# Synthetic pilots at three skills (0.2 novice, 0.5 okay, 0.9 expert) each fly 30 keyboard
# demonstrations of TASK into one dataset; BC (default flags) learns from each tier alone, from
# all 90 mixed, from the mix selected by grade (good or better; excellent) and from the mix
# weighted by grade, and from the novice with its reaction time answered for (--shift auto);
# every policy and every tier then flies the same 16 held-out episodes.
# Usage: bash docs/experiments/skill_tiers.sh [TASK] [OUT] [EVAL_SEED] (DEMOS=30 EVALS=16: per tier, per agent)
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
TASK=${1:-turn}
OUT=${2:-runs/experiments/skill-tiers-$TASK}
EVAL_SEED=${3:-9100}
TIERS=("0.2 novice 1000" "0.5 okay 2000" "0.9 expert 3000")

for tier in "${TIERS[@]}"; do
  read -r skill name seed <<<"$tier"
  python -m gymfg_il.collect manual --pilot synthetic --device keyboard --task "$TASK" \
    --skill "$skill" --pilot-name "$name" --episodes "${DEMOS:-30}" --seed "$seed" --out "$OUT" --no-progress
done

bc() {  # bc NAME [train bc flags]
  python -m gymfg_il.train bc --dataset "$OUT/dataset" --out "$OUT/policy-$1" --no-progress "${@:2}"
}
bc novice --select pilot=novice
bc okay --select pilot=okay
bc expert --select pilot=expert
bc mixed
bc selected --select grade=good
bc excellent --select grade=excellent
bc weighted --weight grade
bc novice-shifted --select pilot=novice --shift auto

POLICIES=()
for p in novice okay expert mixed selected excellent weighted novice-shifted; do
  POLICIES+=("$OUT/policy-$p")
done
python -m gymfg_il.eval --policy "${POLICIES[@]}" --episodes "${EVALS:-16}" --seed "$EVAL_SEED" \
  --json "$OUT/eval-policies.json" --no-progress
for tier in "${TIERS[@]}"; do
  read -r skill name _ <<<"$tier"
  python -m gymfg_il.eval --task "$TASK" --pilot synthetic --device keyboard --skill "$skill" \
    --episodes "${EVALS:-16}" --seed "$EVAL_SEED" --json "$OUT/eval-pilot-$name.json" --no-progress
done
python docs/experiments/skill_tiers.py "$OUT"
