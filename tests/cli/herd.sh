#!/usr/bin/env bash
# animrt herd: a flock run writes the CSV (header, one row per agent per
# output step), the top view and the summary; a bad scene is refused with
# exit 2 naming the file, line and key. animrt run --herd: the quadruped,
# walking on physics as one agent of a crowd, is steered toward its goal; the
# pony (configs/robots/pony.yaml) turns round a wall to reach its goal.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$animrt" herd "$root/configs/herd/flock.yaml" --duration 30 --out "$tmp/h.csv" \
  --svg "$tmp/h.svg" --summary-json "$tmp/h.json" --quiet 2>&1) || fail "herd failed: $out"
[[ $(head -1 "$tmp/h.csv") == "time_s,agent,group,x_m,y_m,heading_rad,speed_mps,turn_rps" ]] ||
  fail "CSV header: $(head -1 "$tmp/h.csv")"
# 30 agents x (1 + 30 s x 10 Hz) output steps.
rows=$(($(wc -l < "$tmp/h.csv") - 1))
[[ $rows -eq 9030 ]] || fail "expected 9030 rows, found $rows"
[[ $(sed -n 2p "$tmp/h.csv") == 0.000,flock.0,flock,* ]] || fail "first row: $(sed -n 2p "$tmp/h.csv")"
[[ $(tail -1 "$tmp/h.csv") == 30.000,flock.29,flock,* ]] || fail "last row: $(tail -1 "$tmp/h.csv")"
grep -q '<svg' "$tmp/h.svg" || fail "no SVG"
[[ $(grep -c '<polyline' "$tmp/h.svg") -eq 30 ]] || fail "expected 30 trails"
/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['groups'][0]['agents']==30 and 'collisions' in j" \
  "$tmp/h.json" || fail "summary JSON"
[[ $out == *"flock (reynolds, 30 figures)"* ]] || fail "summary lines: $out"

# A bad scene: one error line with file, line and key, exit 2.
sed 's/count: 30/count: thirty/' "$root/configs/herd/flock.yaml" > "$tmp/bad.yaml"
sed -i "s|../gaits/pony.yaml|$root/configs/gaits/pony.yaml|" "$tmp/bad.yaml"
out=$("$animrt" herd "$tmp/bad.yaml" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"bad.yaml:13:"*"groups[0].count"* ]] || fail "bad scene (exit $code): $out"

# The robot as one agent: lockstep physics, the herd steers its gait.
out=$("$animrt" run "$root/configs/robots/quadruped.yaml" --lockstep --no-realtime --duration 18 \
  --physics "$root/configs/models/quadruped.xml" --herd "$root/configs/herd/walker.yaml" \
  --agent walker.0 2>&1) || fail "run --herd failed: $out"
line=$(grep -o 'distance to its goal [0-9.]* -> [0-9.]* m' <<< "$out") || fail "no herd report: $out"
read -r before after < <(sed 's/distance to its goal \([0-9.]*\) -> \([0-9.]*\) m/\1 \2/' <<< "$line")
/usr/bin/python3 -c "import sys; b,a=map(float,sys.argv[1:]); sys.exit(0 if a < b - 0.8 else 1)" "$before" "$after" ||
  fail "the robot did not close on its goal: $line"
[[ $out == *"measured by physics"* ]] || fail "the agent's pose is not the physics': $out"

# The pony, which turns: a wall stands between it and its goal, so the herd
# walks it round the wall (off its heading and back) to the goal, on physics.
out=$("$animrt" run "$root/configs/robots/pony.yaml" --lockstep --no-realtime --duration 45 \
  --physics "$root/configs/models/pony.xml" --herd "$root/configs/herd/pony_walker.yaml" \
  --agent pony.0 2>&1) || fail "pony run --herd failed: $out"
line=$(grep -o 'heading [-0-9.]* rad, .*distance to its goal [0-9.]* -> [0-9.]* m' <<< "$out") ||
  fail "no pony herd report: $out"
read -r heading before after < <(sed 's/heading \([-0-9.]*\) rad, .*distance to its goal \([0-9.]*\) -> \([0-9.]*\) m/\1 \2 \3/' <<< "$line")
/usr/bin/python3 -c "import sys; h,b,a=map(float,sys.argv[1:]); sys.exit(0 if b > 3.9 and a < 0.5 and abs(h) > 0.15 else 1)" \
  "$heading" "$before" "$after" || fail "the pony did not turn its way to its goal: $line"
[[ $out == *"falls 0"* ]] || fail "the pony fell: $out"

out=$("$animrt" run "$root/configs/robots/quadruped.yaml" --lockstep --duration 1 \
  --herd "$root/configs/herd/walker.yaml" --agent nobody.3 2>&1)
code=$?
[[ $code -eq 2 && $out == *"no agent named 'nobody.3'"* ]] || fail "unknown agent (exit $code): $out"
echo "herd: ok"
