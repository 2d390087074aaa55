#!/usr/bin/env bash
# The balance reflex on the runtime, end to end in lockstep on MuJoCo: the
# horse with a simulated IMU on the physics' torso walks a neighbour of its
# balanced seed (tests/data/gaits/horse_neighbour_balance.yaml, a walk that
# falls without the reflex) and stays up; the same gait without its
# `balance:` line falls, and the tilt watch stops it. A robot without an IMU
# is refused at the gait's balance key before anything moves.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

gait=$root/tests/data/gaits/horse_neighbour_balance.yaml
grep -q '^balance:' "$gait" || fail "the fixture has no balance"
grep -v '^balance:' "$gait" > "$tmp/plain.yaml"
robot() {  # $1 gait file, $2 "imu" (with the tilt watch) or not
  local watch=""
  [[ $2 == imu ]] && watch="\\n  tilt_limit_deg: 40\\n  tilt_time_s: 0.1\\n  on_tilt: hold\\n  tilt_hold_s: 0.2"
  sed -e "s#file: ../gaits/horse_walk.yaml.*#file: $1#" \
    -e "s#start_ramp_s: 2.0 #start_ramp_s: 1.0 #" -e "s#^safety:\$#safety:$watch#" \
    -e "s#^model: ../models/horse.xml#model: $root/configs/models/horse.xml#" \
    "$root/configs/robots/horse.yaml"
  [[ $2 == imu ]] && printf "imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: 0.5}\n"
}
robot "$gait" imu > "$tmp/balanced.yaml"
robot "$tmp/plain.yaml" imu > "$tmp/plain_robot.yaml"
robot "$gait" none > "$tmp/no_imu.yaml"

# No IMU: one error at the gait's balance key, exit 2, nothing started.
"$animrt" validate "$tmp/no_imu.yaml" > "$tmp/v.txt" 2>&1
code=$?
[[ $code == 2 ]] || fail "no IMU: exit $code: $(cat "$tmp/v.txt")"
line=$(grep -n '^balance:' "$gait" | cut -d: -f1)
grep -q "$gait:$line:[0-9]*: balance: this gait balances on the trunk's attitude, and .*no_imu.yaml has no IMU" \
  "$tmp/v.txt" || fail "no IMU error: $(cat "$tmp/v.txt")"
"$animrt" validate "$tmp/balanced.yaml" > "$tmp/v.txt" 2>&1 || fail "balanced: $(cat "$tmp/v.txt")"

walk() {  # $1 robot, $2 name
  "$animrt" run "$1" --backend sim --physics "$root/configs/models/horse.xml" --lockstep \
    --duration 3 --summary-json "$tmp/$2.json" > "$tmp/$2.txt" 2>&1
}
walk "$tmp/balanced.yaml" balanced
code=$?
[[ $code == 0 ]] || fail "with the reflex: exit $code: $(tail -20 "$tmp/balanced.txt")"
grep -q "simulated IMU trunk .* on the physics' torso" "$tmp/balanced.txt" \
  || fail "the IMU is not on the physics: $(cat "$tmp/balanced.txt")"
/usr/bin/python3 - "$tmp/balanced.json" <<'PY' || fail "with the reflex the horse did not stay up"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "duration", s["end_reason"]
assert s["physics"]["falls"] == 0, s["physics"]
assert s["physics"]["motion_forward_m"] > 1.0, s["physics"]
PY

walk "$tmp/plain_robot.yaml" plain
code=$?
/usr/bin/python3 - "$tmp/plain.json" "$code" <<'PY' || fail "without the reflex the horse did not fall"
import json, sys
s = json.load(open(sys.argv[1]))
tilted = any("tilt watch" in f for f in s["faults"])
assert s["physics"]["falls"] > 0 or tilted, s
if tilted:
    assert sys.argv[2] == "4", sys.argv[2]
PY
echo ok
