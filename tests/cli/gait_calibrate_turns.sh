#!/usr/bin/env bash
# animrt gait calibrate --turns 1 tries only the fastest turns: when none is
# usable, it says the table walks the gait straight only and why; the table
# names its gait by a normalised path.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The quadruped's walk cannot turn at its fastest +-4 deg/s on the model.
out=$("$animrt" gait calibrate "$root/configs/robots/quadruped.yaml" \
  --physics "$root/configs/models/quadruped.xml" --speeds 1 --turns 1 \
  --out "$tmp/walk.calibration.yaml" 2>&1) || fail "calibrate failed: $out"
[[ $out == *"1 of 3 points usable"* ]] || fail "unexpected grid: $out"
[[ $out == *"no turn is usable: the table walks the gait straight only (--turns 1 tries only the fastest turns, +-4.0 deg/s"* ]] ||
  fail "a straight-only table without a word: $out"
gait=$(sed -n 's/^gait: "\(.*\)"$/\1/p' "$tmp/walk.calibration.yaml")
[[ -n $gait && $gait != *"/../gaits/"* && $gait == *"configs/gaits/walk.yaml" ]] ||
  fail "the table names its gait as '$gait'"
[[ $(cd "$tmp" && realpath "$gait") == $(realpath "$root/configs/gaits/walk.yaml") ]] ||
  fail "the table's gait path '$gait' does not lead to the gait"
echo "ok"
