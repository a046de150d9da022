#!/bin/bash
# Every generated picture of the README and the docs site, remade from the current code into
# docs/images/ (their own folder; nothing else writes there):
#   altitude_c172p_controller.png, roll_c172p_controller.png  the paper's Figure 1: the
#       controller on the first 4 evaluation seeds (eval --plots)
#   approach_c172p_tracks.png  the approach's expert and two policies cloned from 50 of its
#       demonstrations (MLP, chunking), ground track and vertical profile on seeds 5000-5001
#   camera_strip.png  the headless camera along an approach (camera_strip.py)
#   gui.png  the controls GUI in flight (python -m gymfg_il.cockpit.screenshot)
#   window_approach.png, window_formation.png  the window 20 s into the approach and the
#       formation, flown by the synthetic pilot from what the window shows (screenshot --task)
#   web_approach.png, web_formation.png  the web cockpit in Chromium 8 s into the approach and
#       the formation, hands off (web_screenshot.py; needs Chromium; real time, so it differs a
#       little from run to run)
#   flightgear.png  only with FLIGHTGEAR=1: FlightGear fed by JSBSim, from its test (needs fgfs
#       and Xvfb; a real-time screenshot, so it differs from run to run)
# Everything but the FlightGear picture is flown from fixed seeds, so the same code makes the
# same pictures. About 8 minutes on two busy cores, most of it training the two policies.
# Usage: bash docs/experiments/pictures.sh [OUT]   (make pictures; OUT defaults to docs/images)
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
OUT=${1:-docs/images}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$OUT"
for TASK in altitude roll; do
  python -m gymfg_il.eval --task "$TASK" --episodes 4 --plots "$WORK/plots" --no-progress
  cp "$WORK/plots/${TASK}_c172p_controller.png" "$OUT/"
done
D="$WORK/approach-c172p-50"
python -m gymfg_il.collect autopilot --task approach --episodes 50 --seed 0 --out "$D" \
  --no-progress > /dev/null
for POLICY in mlp chunk; do
  python -m gymfg_il.train bc --dataset "$D/dataset" --policy "$POLICY" --out "$D-$POLICY" \
    --no-progress > /dev/null
done
python -m gymfg_il.eval --policy "$D-mlp" --policy "$D-chunk" --episodes 2 --seed 5000 \
  --plots "$WORK/plots" --no-progress
cp "$WORK/plots/approach_c172p_tracks.png" "$OUT/"
python docs/experiments/camera_strip.py "$OUT/camera_strip.png"
python -m gymfg_il.cockpit.screenshot "$OUT/gui.png"
for TASK in approach formation; do
  python -m gymfg_il.cockpit.screenshot "$OUT/window_$TASK.png" --task "$TASK"
done
if command -v chromium >/dev/null; then
  for TASK in approach formation; do
    python docs/experiments/web_screenshot.py "$OUT/web_$TASK.png" --task "$TASK"
  done
fi
if [ "${FLIGHTGEAR:-0}" = 1 ]; then
  GYMFG_SCREENSHOT="$(realpath "$OUT")/flightgear.png" python -m pytest -q -m flightgear \
    tests/flightgear/test_flightgear.py::test_flightgear_follows_jsbsim
fi
echo "pictures in $OUT"
