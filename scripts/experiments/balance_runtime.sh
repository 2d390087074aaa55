#!/usr/bin/env bash
# The balance reflex on the runtime against the fitness walk, over neighbours
# of the horse's balanced seed (docs/results/balance_runtime.md).
#
# Usage: ANIMRT=build/bin/animrt [START_RAMP_S=2] [TILT_DEG=] [MEASURE=1] [IMU_LATENCY_MS=] \
#          [ONLY_REFLEX=0] [BALANCE='{tilt_m: 0.3, tilt_rate_m_s: 0.1}'] \
#          [MEASURE_ROBOT=configs/robots/horse.yaml] [MEASURE_ARGS=] [RUN=1] \
#          balance_runtime.sh OUT_DIR COUNT RNG_SEED [DURATION_S]
# For each neighbour: `gait measure` (3 starts) with and without the reflex,
# then `animrt run --physics --lockstep` of the horse with a simulated IMU on
# the physics' torso, with and without it. Prints one table row a neighbour.
# BALANCE replaces the neighbours' reflex gains (the seed's by default).
# MEASURE_ROBOT: `gait measure --robot` (the targets through that robot's
# joint limits at its loop rate, as the runtime plays them); MEASURE_ARGS:
# more of its options; RUN=0 walks only `gait measure`; ONLY_REFLEX=1
# walks neither without the reflex.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
animrt=${ANIMRT:-$root/build/bin/animrt}
out=$1 count=$2 seed=$3 duration=${4:-6}
ramp=${START_RAMP_S:-2.0} tilt=${TILT_DEG:-} do_measure=${MEASURE:-1}
latency=${IMU_LATENCY_MS:-} only_reflex=${ONLY_REFLEX:-0}
measure_robot=${MEASURE_ROBOT:-} do_run=${RUN:-1} measure_args=${MEASURE_ARGS:-}
python3 "$root/scripts/experiments/balance_neighbours.py" \
  "$root/configs/gaits/horse_seed_balance.yaml" "$out" "$count" "$seed"
if [[ -n ${BALANCE:-} ]]; then
  for g in "$out"/n[0-9]*.yaml; do
    [[ $g == *_plain.yaml ]] || sed -i "s/^balance:.*/balance: $BALANCE/" "$g"
  done
fi
robot() {  # $1 gait file -> the horse robot with an IMU, on stdout
  local watch=""
  [[ -n $tilt ]] && watch="\\n  tilt_limit_deg: $tilt\\n  tilt_time_s: 0.1\\n  on_tilt: hold"
  sed -e "s#file: ../gaits/horse_walk.yaml.*#file: $1#" \
    -e "s#start_ramp_s: 2.0 #start_ramp_s: $ramp #" -e "s#^safety:\$#safety:$watch#" \
    -e "s#^model: ../models/horse.xml#model: $root/configs/models/horse.xml#" \
    "$root/configs/robots/horse.yaml"
  local sim=""
  [[ -n $latency ]] && sim=", sim: {latency_ms: $latency}"
  printf "imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: 0.5%s}\n" "$sim"
}
measure() {  # $1 gait -> "falls/starts"
  [[ $do_measure == 1 ]] || { echo "-"; return; }
  "$animrt" gait measure "$1" --physics "$root/configs/models/horse.xml" --starts 3 \
    ${measure_robot:+--robot "$measure_robot"} $measure_args 2>&1 |
    sed -n 's/.*falls: \([0-9]* of [0-9]*\).*/\1/p' | head -1
}
run() {  # $1 gait -> "falls first_fall_s forward_m"
  [[ $do_run == 1 ]] || { echo "-"; return; }
  robot "$1" > "$out/robot.yaml"
  "$animrt" run "$out/robot.yaml" --backend sim --physics "$root/configs/models/horse.xml" \
    --lockstep --duration "$duration" --summary-json "$out/s.json" > "$out/run.txt" 2>&1
  python3 -c '
import json, sys
p = json.load(open(sys.argv[1]))["physics"]
s = json.load(open(sys.argv[1]))
tilt = " tilt" if any("tilt watch" in f for f in s["faults"]) else ""
print(p["falls"], "%.2f" % p["first_fall_s"], "%.2f" % p["motion_forward_m"] + tilt)' "$out/s.json"
}
echo "| neighbour | gait measure falls, reflex | without | runtime falls, reflex (first fall s, forward m) | without |"
echo "|---|---|---|---|---|"
for ((n = 0; n < count; ++n)); do
  echo "| n$n | $(measure "$out/n$n.yaml") |" \
    "$([[ $only_reflex == 1 ]] && echo - || measure "$out/n${n}_plain.yaml") |" \
    "$(run "$out/n$n.yaml") | $([[ $only_reflex == 1 ]] && echo - || run "$out/n${n}_plain.yaml") |"
done
