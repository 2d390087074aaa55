#!/usr/bin/env bash
# animrt gait calibrate: a small grid on the quadruped model writes a table
# that loads back; a gait without steering is refused with exit 2.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

robot=$root/configs/robots/quadruped.yaml
model=$root/configs/models/quadruped.xml
out=$("$animrt" gait calibrate "$robot" --physics "$model" --speeds 2 --turns 1 \
  --out "$tmp/walk.calibration.yaml" 2>&1) || fail "calibrate failed: $out"
[[ $out == *"of 6 points usable"* ]] || fail "unexpected output: $out"
[[ $(grep -c 'speed_m_s: ' "$tmp/walk.calibration.yaml") -eq 6 ]] || fail "not 6 points"
grep -q '^tolerance: 0.15$' "$tmp/walk.calibration.yaml" || fail "no tolerance"
# Same grid, same numbers: the physics is deterministic.
"$animrt" gait calibrate "$robot" --physics "$model" --speeds 2 --turns 1 \
  --out "$tmp/again.yaml" > /dev/null 2>&1 || fail "second calibrate failed"
diff <(grep speed_m_s "$tmp/walk.calibration.yaml") <(grep speed_m_s "$tmp/again.yaml") > /dev/null ||
  fail "two calibrations differ"

out=$("$animrt" gait calibrate "$robot" --gait "$root/configs/gaits/quadruped_seed.yaml" \
  --physics "$model" --out "$tmp/x.yaml" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"quadruped_seed.yaml"*"steering"* ]] || fail "unsteerable gait (exit $code): $out"
echo "gait_calibrate: ok"
