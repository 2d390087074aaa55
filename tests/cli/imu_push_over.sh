#!/usr/bin/env bash
# In lockstep, a figure with a simulated IMU pushed over by the robot
# file's script: the tilt watch stops the walk (exit 4, named in the
# summary) and the joints hold where they were instead of ramping home. The
# same figure level walks its whole duration.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$tmp/robots"
ln -s "$root/configs/gaits" "$tmp/gaits"
ln -s "$root/configs/models" "$tmp/models"
# The IMU is given a long stale timeout: a loaded machine can starve the
# simulated part's thread for a while, and staleness is not what this tests.
robot() {  # $1: the IMU's sim section
  sed 's/^safety:$/safety:\n  tilt_limit_deg: 45\n  tilt_time_s: 0.1\n  on_tilt: hold\n  tilt_hold_s: 0.5/' \
    "$root/configs/robots/quadruped.yaml"
  printf "imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: 0.5%s}\n" "$1"
}
robot ", sim: {push_at_s: 0.5, push_axis: roll, push_rate_deg_s: 180, push_to_deg: 90}" \
  > "$tmp/robots/pushed.yaml"
robot "" > "$tmp/robots/level.yaml"

"$animrt" run "$tmp/robots/pushed.yaml" --backend sim --lockstep --duration 3 \
  --telemetry "$tmp/p.csv" --summary-json "$tmp/p.json" > "$tmp/p.txt" 2>&1
code=$?
[[ $code == 4 ]] || fail "pushed over: exit $code, expected 4: $(cat "$tmp/p.txt")"
grep -q "tilt watch: the trunk tilted" "$tmp/p.txt" || fail "no tilt line: $(cat "$tmp/p.txt")"
/usr/bin/python3 - "$tmp/p.json" "$tmp/p.csv" <<'PY' || fail "pushed-over summary or telemetry wrong"
import csv, json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "fault", s["end_reason"]
assert any("tilt watch" in f for f in s["faults"]), s["faults"]
# Pushed at 0.5 s into the motion, 45 degrees 0.25 s later, watched 0.1 s:
# the motion ended long before its 3 s.
assert s["motion_time_s"] < 1.5, s["motion_time_s"]
rows = list(csv.reader(open(sys.argv[2])))
head, rows = rows[0], [[float(x) for x in r] for r in rows[1:]]
cmd = [i for i, h in enumerate(head) if h.endswith("_cmd_rad")]
# Held, not ramped home: the last commands are where the joints were when
# the hold began, not all at home (0).
assert any(abs(rows[-1][i]) > 0.05 for i in cmd), rows[-1]
PY

"$animrt" run "$tmp/robots/level.yaml" --backend sim --lockstep --duration 2 \
  --summary-json "$tmp/l.json" > "$tmp/l.txt" 2>&1 || fail "level run: $(cat "$tmp/l.txt")"
grep -q "simulated IMU trunk" "$tmp/l.txt" || fail "no IMU: $(cat "$tmp/l.txt")"
/usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "duration" and s["exit_code"] == 0, s
' "$tmp/l.json" || fail "level summary wrong"

# On hardware an IMU needs its port: refused before anything opens.
"$animrt" run "$tmp/robots/level.yaml" --backend hardware --duration 1 > "$tmp/h.txt" 2>&1
code=$?
[[ $code == 2 ]] || fail "hardware without an IMU port: exit $code: $(cat "$tmp/h.txt")"
grep -q "level.yaml:[0-9]*:[0-9]*: imus\[0\].port: expected the serial port" "$tmp/h.txt" \
  || fail "no port error: $(cat "$tmp/h.txt")"
echo ok
