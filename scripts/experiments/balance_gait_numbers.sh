#!/usr/bin/env bash
# The balanced horse's speed, stride and duty on the runtime against the
# fitness walk's (docs/results/balance_runtime.md, "Speed, stride and duty").
#
# Usage: ANIMRT=build/bin/animrt balance_gait_numbers.sh OUT_DIR
# The seed (configs/gaits/horse_seed_balance.yaml) with its reflex and with its
# balance: line removed, each walked by `gait measure` (10 starts; 3 and 8
# measured cycles) as scored, through the horse's limits (--robot
# configs/robots/horse.yaml), and through them with its IMU (the robot file
# plus the IMU the runtime has), then by `animrt run` of the horse with that
# IMU, lockstep on the physics, 10 and 20 s of motion.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
animrt=${ANIMRT:-$root/build/bin/animrt}
out=$1
mkdir -p "$out"
model=$root/configs/models/horse.xml
imu='imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: 0.5}\n'
sed '/^balance:/d' "$root/configs/gaits/horse_seed_balance.yaml" > "$out/plain.yaml"
{
  sed -e "s#^model: ../models/horse.xml#model: $model#" \
    -e "s#file: ../gaits/horse_walk.yaml#file: $root/configs/gaits/horse_walk.yaml#" \
    "$root/configs/robots/horse.yaml"
  printf "$imu"
} > "$out/imu.yaml"
measure() {  # $1 gait, more options -> "falls | speed | stride | duty"
  local g=$1; shift
  "$animrt" gait measure "$g" --physics "$model" "$@" | awk '
    /^falls:/ {falls = $2 " of " $4}
    /^walks:/ {speed = $3 " (sd " $5; stride = $8 " (sd " $10; duty = $13 " (sd " $15}
    END {print falls " | " speed " | " stride " | " duty}'
}
run() {  # $1 gait, $2 seconds of motion -> "falls | speed | stride | duty"
  sed "s#file: [^ ]*horse_walk.yaml.*#file: $1#" "$out/imu.yaml" > "$out/robot.yaml"
  "$animrt" run "$out/robot.yaml" --backend sim --physics "$model" --lockstep --duration "$2" \
    --summary-json "$out/s.json" > "$out/run.txt" 2>&1
  python3 -c '
import json, sys
p = json.load(open(sys.argv[1]))["physics"]
print("%d | %.3f | %.3f | %.3f" % (p["falls"], p["average_speed_m_s"], p["stride_length_m"], p["duty_factor"]))' "$out/s.json"
}
echo "| walk | gait | falls | speed m/s | stride m | duty |"
echo "|---|---|---|---|---|---|"
for gait in "$root/configs/gaits/horse_seed_balance.yaml" "$out/plain.yaml"; do
  name=$([[ $gait == */plain.yaml ]] && echo "without the reflex" || echo "with the reflex")
  for cycles in 3 8; do
    echo "| gait measure, $cycles cycles, as scored | $name | $(measure "$gait" --measure-cycles $cycles) |"
    echo "| gait measure, $cycles cycles, --robot horse.yaml | $name | $(measure "$gait" --measure-cycles $cycles --robot "$root/configs/robots/horse.yaml") |"
    echo "| gait measure, $cycles cycles, --robot with the IMU | $name | $(measure "$gait" --measure-cycles $cycles --robot "$out/imu.yaml") |"
  done
  for s in 10 20; do echo "| animrt run, $s s of motion | $name | $(run "$gait" $s) |"; done
done
