#!/bin/bash
# LeRobot's ACT, trained with LeRobot's own lerobot-train on CPU, beside our MLP and chunking
# policies and the expert: 50 expert demonstrations of a maneuver (default flags), then our
# eval on held-out seeds. The figures of docs/results/act.md.
# Usage: bash docs/experiments/act.sh [OUT] [TASK] [EVAL_SEED] [STEPS]
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-runs/experiments/act}
TASK=${2:-turn}
EVAL_SEED=${3:-5000}
STEPS=${4:-3000}
D="$OUT/$TASK-c172p"
[ -d "$D/dataset" ] || python -m gymfg_il.collect autopilot --task "$TASK" --episodes 50 \
  --seed 0 --out "$D" --no-progress
for POLICY in mlp chunk; do
  [ -f "$D-$POLICY/config.json" ] || python -m gymfg_il.train bc --dataset "$D/dataset" \
    --policy "$POLICY" --out "$D-$POLICY" --no-progress
done
# ACT sized for 14 numbers in and 4 out (its default is a 40M-parameter image model), a
# 1 s chunk flown with temporal ensembling, every input normalised (ENV included)
if [ ! -d "$D-act/checkpoints/last" ]; then
  START=$(date +%s)
  lerobot-train --policy.type=act --dataset.repo_id="gymfg/$TASK-c172p" \
    --dataset.root="$D/dataset" --output_dir="$D-act" --policy.device=cpu \
    --policy.push_to_hub=false --steps="$STEPS" --batch_size=64 --num_workers=0 \
    --save_freq="$STEPS" --log_freq=500 --policy.optimizer_lr=1e-4 \
    --policy.dim_model=128 --policy.n_heads=4 --policy.dim_feedforward=512 \
    --policy.n_encoder_layers=2 --policy.n_decoder_layers=1 --policy.n_vae_encoder_layers=2 \
    --policy.chunk_size=10 --policy.n_action_steps=1 --policy.temporal_ensemble_coeff=0.01 \
    '--policy.normalization_mapping={"VISUAL": "MEAN_STD", "STATE": "MEAN_STD", "ENV": "MEAN_STD", "ACTION": "MEAN_STD"}'
  echo "lerobot-train: $(( $(date +%s) - START )) s for $STEPS steps" | tee "$D-act/train_time.txt"
fi
python -m gymfg_il.eval --policy "$D-mlp" "$D-chunk" "$D-act" --episodes 16 \
  --seed "$EVAL_SEED" --json "$D.eval.json" --no-progress
