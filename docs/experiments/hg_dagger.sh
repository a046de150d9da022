#!/bin/bash
# Human-gated DAgger against plain BC on the same number of demonstrator frames, with the
# synthetic pilot on the altitude task (docs/results/defaults.md, "Human-gated DAgger").
# Usage: bash docs/experiments/hg_dagger.sh [OUT]
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
H=${1:-runs/experiments/hg_dagger}
if [ -e "$H" ]; then echo "$H exists: give a new folder" >&2; exit 2; fi
fly() { python -m gymfg_il.collect manual --pilot synthetic --device keyboard --task altitude \
  --no-progress "$@" | tail -1; }
fly --episodes 10 --seed 0 --out "$H/base"
python -m gymfg_il.train bc --dataset "$H/base/dataset" --out "$H/p0" --no-progress | grep "^trained"
cp -r "$H/base" "$H/hg"
fly --episodes 10 --seed 100 --assist "$H/p0" --out "$H/hg"  # the pilot takes over (T)
taken=$(python -c "
from gymfg_il.learning.data import load_frames
print(len(load_frames('$H/hg/dataset').demonstrated()) - len(load_frames('$H/base/dataset')))")
extra=$(((taken + 1349) / 2700))  # 90-s episodes at 30 fps
echo "takeover frames: $taken; plain BC gets $extra more demonstrations"
cp -r "$H/base" "$H/bc"
if [ "$extra" -gt 0 ]; then fly --episodes "$extra" --seed 100 --out "$H/bc"; fi
python -m gymfg_il.eval --policy "$H/p0" --episodes 16 --seed 600 --no-progress | grep "/ controller"
for arm in hg bc; do
  python -m gymfg_il.train bc --dataset "$H/$arm/dataset" --out "$H/p-$arm" --no-progress | grep "^trained"
  python -m gymfg_il.eval --policy "$H/p-$arm" --episodes 16 --seed 600 --no-progress |
    grep "/ controller"
done
