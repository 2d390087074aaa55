#!/usr/bin/env bash
# animrt gait measure: walks a gait from perturbed starts and reports falls
# and the walk beside the Froude predictions; a model that cannot stand is
# reported as falling; bad input is exit 2 naming the file.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

gait=$root/configs/gaits/quadruped_evolved.yaml
model=$root/configs/models/quadruped.xml
out=$("$animrt" gait measure "$gait" --physics "$model" --starts 3 2>&1) || fail "measure failed: $out"
[[ $out == *"falls: 0 of 3"* ]] || fail "the evolved quadruped gait fell: $out"
[[ $out == *"Froude 0.060 predicts"* ]] || fail "no Froude prediction: $out"
# Three different starts give three different walks.
[[ $(grep -cE '^ +[123] +no ' <<< "$out") -eq 3 ]] || fail "not three walk rows: $out"
[[ $(grep -E '^ +[123] +no ' <<< "$out" | awk '{print $4}' | sort -u | wc -l) -ge 2 ]] ||
  fail "perturbed starts all walked the same: $out"

# Legs too weak to carry the body: every walk falls.
sed 's/forcerange="-[0-9.]* [0-9.]*"/forcerange="-0.05 0.05"/' "$model" > "$tmp/weak.xml"
out=$("$animrt" gait measure "$gait" --physics "$tmp/weak.xml" --starts 2 2>&1) ||
  fail "measure on the weak model failed: $out"
[[ $out == *"falls: 2 of 2"* ]] || fail "a model that cannot stand did not fall: $out"

# The balance reflex fed the attitude late (a robustness measure): without
# the flag, or at 0 ms, the walk is the fitness walk; 60 ms late it is another.
horse=$root/configs/models/horse.xml
seed=$root/configs/gaits/horse_seed_balance.yaml
walks() { grep -E '^ +1 ' <<< "$1"; }
one=(--physics "$horse" --starts 1 --measure-cycles 1)
now=$("$animrt" gait measure "$seed" "${one[@]}" 2>&1) || fail "horse: $now"
zero=$("$animrt" gait measure "$seed" "${one[@]}" --balance-delay-ms 0 2>&1) || fail "0 ms: $zero"
late=$("$animrt" gait measure "$seed" "${one[@]}" --balance-delay-ms 60 2>&1) || fail "60 ms: $late"
[[ $(walks "$now") == "$(walks "$zero")" ]] || fail "0 ms late is not the fitness walk: $zero"
[[ $late == *"reads the trunk's attitude 60 ms late"* ]] || fail "the delay is not said: $late"
[[ $(walks "$now") != "$(walks "$late")" ]] || fail "60 ms late walked the same: $late"
# Read once a physics step (2 ms) it is the fitness walk; once every 10 ms another.
step=$("$animrt" gait measure "$seed" "${one[@]}" --balance-period-ms 2 2>&1) || fail "2 ms: $step"
slow=$("$animrt" gait measure "$seed" "${one[@]}" --balance-period-ms 10 2>&1) || fail "10: $slow"
[[ $(walks "$now") == "$(walks "$step")" ]] || fail "every step is not the fitness walk: $step"
[[ $(walks "$now") != "$(walks "$slow")" ]] || fail "every 10 ms walked the same: $slow"

# Through the robot file's joint limits at its loop rate: another walk, and
# a robot without one of the model's joints is refused naming file and joint.
robot=$root/configs/robots/horse.yaml
played=$("$animrt" gait measure "$seed" "${one[@]}" --robot "$robot" 2>&1) || fail "robot: $played"
[[ $played == *"joint limits at 200 Hz"* ]] || fail "the limits are not said: $played"
[[ $(walks "$now") != "$(walks "$played")" ]] || fail "the limits changed nothing: $played"
sed -e 's/^  lf_elbow:/  lf_elbow_renamed:/' -e "s#\.\./#$root/configs/#g" "$robot" > "$tmp/robot.yaml"
out=$("$animrt" gait measure "$seed" "${one[@]}" --robot "$tmp/robot.yaml" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"robot.yaml"* && $out == *'"lf_elbow"'* ]] ||
  fail "a robot without a model joint (exit $code): $out"

out=$("$animrt" gait measure "$tmp/missing.yaml" --physics "$model" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"missing.yaml"* ]] || fail "missing gait (exit $code): $out"
echo "gait_measure: ok"
