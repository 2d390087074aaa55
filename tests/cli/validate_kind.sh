#!/usr/bin/env bash
# animrt validate of a file that is not a robot file (a gait, a show, a herd
# scene, an evolve run file) says what kind of file it got and what it
# expected, in one line, exit 2.
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
echo "ok"
