#!/usr/bin/env bash
# The trunk's IMU falls silent in the middle of a balanced walk (lockstep,
# MuJoCo): the simulated BNO08x stops sending at 1.5 s (its robot-file sim
# section, as a part whose cable came loose). The reflex holds the last
# attitude (the telemetry's trunk quaternion stays at its last value, no
# jump in the commands); after the IMU's stale timeout (0.25 s by default)
# the run faults with one line naming the IMU and ramps home (exit 4); the
# summary counts the reports that never came. A walking figure does not
# walk on blind.
set -uo pipefail
animrt=$1
root=$(cd "$2" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

gait=$root/tests/data/gaits/horse_neighbour_balance.yaml
robot() {  # $1: the IMU's sim section
  sed -e "s#file: ../gaits/horse_walk.yaml.*#file: $gait#" \
    -e "s#start_ramp_s: 2.0 #start_ramp_s: 1.0 #" \
    -e "s#^model: ../models/horse.xml#model: $root/configs/models/horse.xml#" \
    "$root/configs/robots/horse.yaml"
  printf "imus:\n  - {name: trunk, protocol: bno08x_rvc%s}\n" "$1"
}
robot ", sim: {silent_at_s: 1.5}" > "$tmp/horse.yaml"
robot "" > "$tmp/reference.yaml"
# The same walk with its IMU reporting, to the stale timeout's end.
"$animrt" run "$tmp/reference.yaml" --backend sim --physics "$root/configs/models/horse.xml" \
  --lockstep --duration 0.8 --telemetry "$tmp/r.csv" > "$tmp/r.txt" 2>&1 \
  || fail "the reference walk: $(tail -20 "$tmp/r.txt")"

"$animrt" run "$tmp/horse.yaml" --backend sim --physics "$root/configs/models/horse.xml" \
  --lockstep --duration 3 --telemetry "$tmp/t.csv" --summary-json "$tmp/s.json" \
  > "$tmp/out.txt" 2>&1
code=$?
[[ $code == 4 ]] || fail "exit $code, expected 4: $(tail -30 "$tmp/out.txt")"
[[ $(grep -c "^FAULT " "$tmp/out.txt") == 1 ]] || fail "not one fault line: $(cat "$tmp/out.txt")"
grep -q "^FAULT IMU trunk: no reading for 0.2[5-9][0-9]* s (stale_timeout_s 0.25) at t=1\.[78]" \
  "$tmp/out.txt" || fail "no line naming the IMU: $(grep -i imu "$tmp/out.txt")"
grep -q "^imu trunk: .* missing reports (FAULTED" "$tmp/out.txt" \
  || fail "no IMU summary line: $(cat "$tmp/out.txt")"
/usr/bin/python3 - "$tmp/s.json" "$tmp/t.csv" "$tmp/r.csv" <<'PY' || fail "summary or telemetry wrong"
import csv, json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "fault", s["end_reason"]
imu = s["imus"][0]
assert imu["name"] == "trunk" and imu["faulted"], imu
# 1.5 s of reports at 100 Hz, then none: every report from 1.5 s to the
# end of the ramp home is missing, none before.
assert 145 <= imu["readings"] <= 151, imu
assert imu["missing_reports"] >= 25, imu
assert imu["late_cycles"] >= 40, imu  # 200 Hz cycles past a report and a period
def load(path):
    rows = list(csv.reader(open(path)))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]
head, rows = load(sys.argv[2])
_, reference = load(sys.argv[3])
q = [head.index("trunk_" + c) for c in ("qw", "qx", "qy", "qz")]
silent = [r for r in rows if r[0] > 1.52]
assert len(silent) > 40, len(silent)
held = [silent[0][i] for i in q]
for row in silent:
    assert [row[i] for i in q] == held, "the held attitude changed"
# No jump in the commands when the IMU fell silent: from 1.5 s to the
# fault, no cycle moves a joint further than the same walk with its IMU.
cmd = [i for i, h in enumerate(head) if h.endswith("_cmd_rad")]
def largest_step(rs):
    rs = [r for r in rs if 1.5 <= r[0] <= 1.74]
    return max(abs(b[i] - a[i]) for a, b in zip(rs, rs[1:]) for i in cmd)
assert largest_step(rows) <= 1.1 * largest_step(reference), (largest_step(rows), largest_step(reference))
PY
echo ok
