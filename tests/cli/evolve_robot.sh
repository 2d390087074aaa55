#!/usr/bin/env bash
# animrt evolve --robot scores every gait as that robot's figure plays it
# (its joint limits at its loop rate, the reflex reading the attitude as its
# IMU reports it), the walk `gait measure --robot` walks: the best gait's
# speed, stride and duty are what gait measure --robot finds for it, and
# not what it finds without. The run file's robot: key does the same; a
# robot without one of the model's joints is refused naming file and joint.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

horse=$root/configs/models/horse.xml
sed -e "s#\.\./#$root/configs/#g" "$root/configs/robots/horse.yaml" > "$tmp/robot.yaml"
printf 'imus:\n  - {name: trunk, protocol: bno08x_rvc}\n' >> "$tmp/robot.yaml"
run_file() {  # $1: extra top-level lines
  cat <<YAML
name: played
grammar: $root/configs/grammars/horse_hybrid.bnf
model: $horse
seed_gait: $root/configs/gaits/horse_seed_balance.yaml
search: {seed: 2, population: 2, generations: 0, elites: 1, max_depth: 6}
walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}
$1
YAML
}
run_file "" > "$tmp/evolve.yaml"
run_file "robot: $tmp/robot.yaml" > "$tmp/keyed.yaml"
# "speed stride duty" of the best, rounded as gait measure prints them.
best() { sed -n 's/^best fitness [^:]*: speed \([^ ]*\) m\/s, stride \([^ ]*\) m, duty factor \([^ ]*\),.*/\1 \2 \3/p' <<< "$1" |
  awk '{printf "%.3f %.3f %.3f\n", $1, $2, $3}'; }
measured() {  # $1 gait, more options -> "speed stride duty" of its one walk
  local g=$1; shift
  "$animrt" gait measure "$g" --physics "$horse" --starts 1 --perturb-deg 0 --settle 0.1 \
    --warmup-cycles 1 --measure-cycles 1 "$@" 2>&1 | awk '$1 == 1 && $2 == "no" {print $4, $5, $6}'
}

out=$("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/g.yaml" --threads 1 --robot "$tmp/robot.yaml" 2>&1) ||
  fail "evolve --robot: $out"
[[ $out == *"joint limits at 200 Hz; the balance reflex reads the attitude every 10 ms, 10 ms late"* ]] ||
  fail "the header does not say how the walk is played: $out"
played=$(measured "$tmp/g.yaml" --robot "$tmp/robot.yaml")
plain=$(measured "$tmp/g.yaml")
[[ -n $played && -n $plain ]] || fail "the best gait fell in gait measure: '$played' '$plain'"
[[ $(best "$out") == "$played" ]] || fail "evolve --robot scored $(best "$out"), gait measure --robot $played"
[[ $played != "$plain" ]] || fail "the robot's limits and IMU walked as the physics alone: $plain"
fresh=$(measured "$tmp/g.yaml" --robot "$tmp/robot.yaml" --balance-period-ms 0 --balance-delay-ms 0)
[[ $played != "$fresh" ]] || fail "the IMU's report period and age walked as a fresh attitude: $fresh"

keyed=$("$animrt" evolve "$tmp/keyed.yaml" --out "$tmp/k.yaml" --threads 1 2>&1) || fail "robot: key: $keyed"
[[ $(best "$keyed") == "$played" ]] || fail "robot: scored $(best "$keyed"), --robot $played"
bare=$("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/b.yaml" --threads 1 2>&1) || fail "no robot: $bare"
[[ $(measured "$tmp/b.yaml") == "$(best "$bare")" ]] || fail "without --robot the scoring changed: $bare"

sed -e 's/^  lf_elbow:/  lf_elbow_renamed:/' "$tmp/robot.yaml" > "$tmp/lacking.yaml"
out=$("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/n.yaml" --robot "$tmp/lacking.yaml" 2>&1)
code=$?
# One line naming the robot file, the line of its joints key and the joint.
line=$(grep -n '^joints:' "$tmp/lacking.yaml" | cut -d: -f1)
expected="error: $tmp/lacking.yaml:$line:1: joints: no joint \"lf_elbow\" of the model (--robot needs them all)"
[[ $code -eq 2 && $out == "$expected" ]] ||
  fail "a robot without a model joint (exit $code): '$out', expected '$expected'"
[[ ! -e $tmp/n.yaml ]] || fail "a refused robot wrote a gait"
echo "ok"
