#!/bin/bash
# The cockpit a person flies (docs/results/cockpit.md): the synthetic pilot who sees only the
# window, on every task, and behaviour cloning from its demonstrations.
#   bash docs/experiments/cockpit.sh pilot AIRCRAFT SEED [EPISODES]
#       eval --pilot synthetic --device keyboard on every task: the controller's and the
#       pilot's successes, crashes, the return ratio and the worst return
#   bash docs/experiments/cockpit.sh bc OUT SEED EVAL_SEED [TASK ...]
#       per maneuver: 50 keyboard demonstrations by the pilot (collect manual --pilot
#       synthetic, seeds from SEED), default train bc, then eval of the policy beside the
#       pilot on 16 held-out episodes from EVAL_SEED
set -euo pipefail
export HF_HUB_OFFLINE=1 SDL_VIDEODRIVER=dummy
PY=${PY:-python}
TASKS="turn climb-turn waypoints formation approach altitude heading roll pitch airspeed sideslip"
MANEUVERS="turn climb-turn waypoints formation approach"
row() {  # row JSON LABEL: one line of the table from an eval --json
  $PY - "$1" "$2" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
ok = lambda r: sum(e["success"] for e in r["per_episode"])
line = [sys.argv[2]]
for r in rows:
    worst = min(e["total_return"] for e in r["per_episode"])
    line.append(f"{r['agent']} {ok(r)}/{len(r['per_episode'])} crashed {r['terminated']} "
                f"return {r['mean_return']:.0f} (worst {worst:.0f})")
pilot = [r for r in rows if r["agent"].startswith("pilot:")]
for r in rows:
    if r["agent"].startswith("policy:") and pilot:
        ratio = r["mean_return"] / pilot[0]["mean_return"]
        line.append(f"policy/pilot return {100 * ratio:.1f}%")
print(" | ".join(line))
PY
}
case "${1:-}" in
pilot)
  AIRCRAFT=$2 SEED=$3 N=${4:-16}
  WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
  for T in $TASKS; do
    $PY -m gymfg_il.eval --task "$T" --aircraft "$AIRCRAFT" --pilot synthetic --device keyboard \
      --episodes "$N" --seed "$SEED" --no-progress --json "$WORK/$T.json" > /dev/null
    row "$WORK/$T.json" "$AIRCRAFT $T"
  done ;;
bc)
  OUT=$2 SEED=$3 EVAL_SEED=$4; shift 4
  for T in ${*:-$MANEUVERS}; do
    D="$OUT/$T"
    $PY -m gymfg_il.collect manual --pilot synthetic --device keyboard --task "$T" \
      --episodes 50 --seed "$SEED" --out "$D" --no-progress > /dev/null
    $PY -m gymfg_il.train bc --dataset "$D/dataset" --out "$D-bc" --no-progress > /dev/null
    $PY -m gymfg_il.eval --policy "$D-bc" --pilot synthetic --device keyboard --episodes 16 \
      --seed "$EVAL_SEED" --no-progress --json "$D-eval.json" > /dev/null
    row "$D-eval.json" "c172p $T"
  done ;;
*)
  sed -n '2,10p' "$0"; exit 2 ;;
esac
