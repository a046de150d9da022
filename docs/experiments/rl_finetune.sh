#!/bin/bash
# RL fine-tuning past the demonstrator (docs/results/rl.md).
# 1. Past the demonstrations: BC (default flags) from 10 still-air autopilot demonstrations of
#    the c172p's altitude, heading and approach, fine-tuned by PPO in moderate turbulence.
# 2. Past the pilot: BC from 30 keyboard demonstrations of the turn by a novice synthetic pilot
#    (Skill.of(0.2)), fine-tuned by PPO in still air.
# Beside each: PPO from scratch with the same budget, and the controller in the same air; all
# fly the same held-out seeds (EVAL_SEED..). Each run's curve (every 50k steps, 16 seeds of its
# own) is in its policy folder (curve.json, curve.png); rl_finetune.py prints the table.
# Usage: bash docs/experiments/rl_finetune.sh [OUT] [TASKS]
#   (STEPS=1000000 TURN_STEPS=3000000 EVALS=16 EVAL_SEED=9300 SEEDS=0; TASKS: any of altitude
#   heading approach turn; the turn is flown at 30 Hz and needs about 3M steps; SEEDS="0 1 2"
#   fine-tunes once per seed, and the table gives the worst run beside the mean: one run
#   says little about the next, docs/results/rl.md)
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/rl-finetune}
TASKS=${2:-altitude heading approach turn}
STEPS=${STEPS:-1000000}
TURN_STEPS=${TURN_STEPS:-3000000}
EVALS=${EVALS:-16}
EVAL_SEED=${EVAL_SEED:-9300}
SEEDS=${SEEDS:-0}

for task in $TASKS; do
  dir="$OUT/$task"
  if [ "$task" = turn ]; then  # the novice pilot, in still air, at a person's 30 Hz
    air=none rate=30 steps=$TURN_STEPS
    python -m gymfg_il.collect manual --pilot synthetic --device keyboard --task turn \
      --skill 0.2 --pilot-name novice --episodes 30 --seed 1000 --out "$dir" --no-progress
  else
    air=moderate rate=10 steps=$STEPS
    python -m gymfg_il.collect autopilot --task "$task" --episodes 10 --seed 500 --out "$dir" \
      --no-progress
  fi
  python -m gymfg_il.train bc --dataset "$dir/dataset" --out "$dir/bc" --no-progress
  tuned=()
  for seed in $SEEDS; do  # seed 0 writes ppo, seed K ppo-sK
    name=ppo; [ "$seed" = 0 ] || name="ppo-s$seed"
    python -m gymfg_il.train ppo --init "$dir/bc" --turbulence "$air" --steps "$steps" \
      --seed "$seed" --out "$dir/$name" --no-progress
    tuned+=("$dir/$name")
  done
  python -m gymfg_il.train ppo --task "$task" --aircraft c172p --agent-hz "$rate" \
    --turbulence "$air" --steps "$steps" --out "$dir/scratch" --no-progress
  python -m gymfg_il.eval --policy "${tuned[@]}" "$dir/bc" "$dir/scratch" --turbulence "$air" \
    --episodes "$EVALS" --seed "$EVAL_SEED" --json "$dir/eval.json" --no-progress
done
python docs/experiments/rl_finetune.py "$OUT"
