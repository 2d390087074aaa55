#!/usr/bin/env bash
# animrt validate of a file that is not a robot file (a gait, a show, a herd
# scene, an evolve run file, a cue file) says what kind of file it got and
# what it expected, in one line, exit 2; `validate ROBOT --cues FILE` checks
# a cue file against its robot.
set -uo pipefail
animrt=$1
root=$2
fail() { echo "FAIL: $*"; exit 1; }

check() {
  local file=$1 kind=$2
  out=$("$animrt" validate "$root/configs/$file" 2>&1)
  code=$?
  [[ $code -eq 2 ]] || fail "$file: exit code $code, expected 2: $out"
  [[ $out == "error: $root/configs/$file: expected a robot file"*"found $kind ("* ]] ||
    fail "$file: $out"
  [[ $(echo "$out" | wc -l) -eq 1 ]] || fail "$file: more than one line: $out"
}
check gaits/walk.yaml "a gait file"
check gaits/walk.calibration.yaml "a gait's calibration table"
check shows/hello.yaml "a show"
check herd/flock.yaml "a herd scene"
check evolve/quadruped_free.yaml "an evolve run file"
check modbus/linear_actuator.yaml "a Modbus register map"
check cues/animatronic.yaml "a cue file"
[[ $out == *"; check it with the robot that plays it: animrt validate ROBOT --cues FILE" ]] ||
  fail "cue file without the way to check it: $out"

# A cue file is checked as serve loads it, against its robot's joints.
robot=$root/configs/robots/animatronic.yaml
out=$("$animrt" validate "$robot" --cues "$root/configs/cues/animatronic.yaml" 2>&1) ||
  fail "validate --cues: $out"
[[ $(echo "$out" | tail -1) == "$root/configs/cues/animatronic.yaml: ok (4 cues, idle sway)" ]] ||
  fail "validate --cues: $out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/cues" && cp -r "$root/configs/shows" "$tmp/"
sed 's/^idle: sway/idle: nap/' "$root/configs/cues/animatronic.yaml" > "$tmp/cues/bad.yaml"
out=$("$animrt" validate "$robot" --cues "$tmp/cues/bad.yaml" 2>&1)
code=$?
[[ $code -eq 2 && $(echo "$out" | tail -1) == "error: $tmp/cues/bad.yaml:5:7: idle: no cue named \"nap\" (the cues: sway, hello, look_left, greet)" ]] ||
  fail "validate --cues with a bad idle (exit $code): $out"
sed 's/neck_pan: 45, neck_tilt: 5/snout: 45, neck_tilt: 5/' "$root/configs/cues/animatronic.yaml" > "$tmp/cues/joint.yaml"
out=$("$animrt" validate "$robot" --cues "$tmp/cues/joint.yaml" 2>&1)
[[ $? -eq 2 && $out == *"$tmp/cues/joint.yaml:"*"snout"* ]] || fail "validate --cues, unknown joint: $out"
echo "ok"
