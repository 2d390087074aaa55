#!/usr/bin/env bash
# The horse's gait asks for more speed than its simulated servos turn: the
# run warns before anything moves, and the following-error fault it ends on
# names that cause first.
set -uo pipefail
animrt=$1
root=$2
fail() { echo "FAIL: $*"; exit 1; }

out=$(timeout 120 "$animrt" run "$root/configs/robots/horse.yaml" --lockstep --no-realtime \
  --duration 2 2>&1)
code=$?
[[ $code -eq 4 ]] || fail "exit code $code, expected 4 (a fault): $out"
[[ $out == *"[warning] gait "*"asks joint lh_tarsal for up to 764 deg/s"* ]] ||
  fail "no warning before the run: $out"
[[ $out == *"FAULT bus hind id "*"RMS following error"*"ramped to home (its motion asks for up to "*" deg/s, faster than bus hind's servos turn (344 deg/s, sim.max_speed_dps)? two servos answering"* ]] ||
  fail "the fault does not name the speed first: $out"
echo "ok"
