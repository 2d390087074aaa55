#!/usr/bin/env bash
# animrt validate says, with the numbers, what a run of a valid robot file
# would fault on or lose cycles to: the horse's gait asks for more speed than
# its buses' simulated servos turn, and the pony's 16-servo read does not
# fit the read budget of its 5 ms period. A figure without either gets none.
set -uo pipefail
animrt=$1
root=$2
fail() { echo "FAIL: $*"; exit 1; }

out=$("$animrt" validate "$root/configs/robots/horse.yaml" 2>&1) || fail "horse rejected: $out"
[[ $out == *"warning: gait "*"horse_walk.yaml asks joint lh_tarsal for up to 764 deg/s"*"(8 joints of bus hind over its servos' speed), but the servos of bus hind turn at most 344 deg/s (sim.max_speed_dps, the default)"* ]] ||
  fail "no speed warning for the horse's hind legs: $out"
[[ $(echo "$out" | grep -c '^warning: .*deg/s') -eq 2 ]] || fail "one warning per bus expected: $out"

out=$("$animrt" validate "$root/configs/robots/pony.yaml" 2>&1) || fail "pony rejected: $out"
[[ $out == *"warning: bus legs: a read takes about 3.12 ms (2.70 ms on the wire for 16 devices at 1000000 baud + 0.42 ms measured overhead for 1 transaction), over the read budget of 3.00 ms (60 % of the 5.00 ms period at 200 Hz)"* ]] ||
  fail "no read budget warning for the pony: $out"

out=$("$animrt" validate "$root/configs/robots/quadruped.yaml" 2>&1) || fail "quadruped rejected: $out"
[[ $out != *warning* ]] || fail "the quadruped warned: $out"
echo "ok"
