#!/usr/bin/env bash
# A simulated Modbus drive trips by itself, as a real drive's firmware does:
# the animatronic's torso actuator, in a hot housing (sim.health: a thermal
# model that heats quickly with its current), passes its trip temperature
# while the show drives it, sets fault code 0x4310 and switches its output
# off; the run reads the code with the drive's health and ends with exit 4
# naming the slave and the fault by the map's name for it, while the other
# joints ramp home. No temperature limit is set on the host: only the
# drive's own trip can end the run. The same drive with a higher trip
# temperature plays the show to its end.
set -uo pipefail
animrt=$1
root=$(cd "$2" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$tmp/robots"
for d in shows modbus; do ln -s "$root/configs/$d" "$tmp/$d"; done
robot() {  # $1: the drive's trip temperature
  /usr/bin/python3 - "$root/configs/robots/animatronic.yaml" "$1" <<'PY'
import sys
text = open(sys.argv[1]).read()
hot = ("    health: packed\n    sim: {time_constant_s: 0.05, max_speed_dps: 40, health: "
       "{current_per_rad_s: 5, heat_c_per_a2: 100, thermal_tau_s: 0.3, trip_c: %s}}\n" % sys.argv[2])
old = "    sim: {time_constant_s: 0.05, max_speed_dps: 40}\n"
assert old in text
text = text.replace(old, hot, 1)
print(text, end="")
PY
}
robot 55 > "$tmp/robots/hot.yaml"
robot 120 > "$tmp/robots/cool.yaml"

"$animrt" run "$tmp/robots/hot.yaml" --backend sim --lockstep --duration 3 --no-realtime \
  --summary-json "$tmp/s.json" > "$tmp/out.txt" 2>&1
code=$?
[[ $code == 4 ]] || fail "exit $code, expected 4: $(cat "$tmp/out.txt")"
grep -q "bus torso id 1 (torso_lean): device error bits 0x4310 (driver overtemperature)" \
  "$tmp/out.txt" || fail "no fault naming the drive and its trip: $(cat "$tmp/out.txt")"
/usr/bin/python3 - "$tmp/s.json" <<'PY' || fail "summary wrong"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["exit_code"] == 4 and s["end_reason"] == "fault", s["end_reason"]
assert len(s["faults"]) == 1, s["faults"]
for d in s["devices"]:
    assert d["faulted"] == (d["joint"] == "torso_lean"), d
lean = [d for d in s["devices"] if d["joint"] == "torso_lean"][0]["readings"]
# It tripped on its own model, heated from ambient by the show (it cools
# at once with its output off, so the last reading is just below the trip).
assert lean["max_temperature_c"] > 50 and lean["min_temperature_c"] < 37, lean
# While the show drove it (after the start ramp), not at rest.
assert 0.2 < s["motion_time_s"] < 2.5, s["motion_time_s"]
PY

"$animrt" run "$tmp/robots/cool.yaml" --backend sim --lockstep --duration 3 --no-realtime \
  --summary-json "$tmp/c.json" > "$tmp/c.txt" 2>&1 || fail "trip at 120 C: $(cat "$tmp/c.txt")"
echo ok
