#!/usr/bin/env bash
# Device health from the robot file to the exit code: a quadruped whose bus
# reads health packed, with limits in the safety section and an overheat
# injected in the sim section, runs on the simulated backend in lockstep;
# the run ends with exit 4 naming the servo and its temperature, its
# telemetry carries five health columns per servo after the joints', and
# the JSON summary each servo's temperature range, peak current and lowest
# voltage. A bad health key stops the load with its file, line and column.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$tmp/robots"
cp -r "$root/configs/gaits" "$tmp/gaits"
[[ -d $root/configs/models ]] && cp -r "$root/configs/models" "$tmp/models"
/usr/bin/python3 - "$root/configs/robots/quadruped.yaml" "$tmp/robots/hot.yaml" <<'PY'
import sys
text = open(sys.argv[1]).read()
text = text.replace("  stop_ramp_s: 2.0 ", "  stop_ramp_s: 0.5 \n  health: {temperature_warn_c: 60, temperature_fault_c: 70}\n  #", 1)
text = text.replace("  start_ramp_s: 2.0 ", "  start_ramp_s: 0.5 \n  #", 1)
text = text.replace("    timeout_ms: 4 ", "    health: packed\n    timeout_ms: 4 ", 1)
text = text.replace("      return_delay_us: 0 ",
                    "      inject:\n        - {id: 9, at_s: 1.0, temperature_c: 75}\n      return_delay_us: 0 ", 1)
assert "health: packed" in text and "inject:" in text and "temperature_fault_c" in text
open(sys.argv[2], "w").write(text)
PY
"$animrt" run "$tmp/robots/hot.yaml" --backend sim --lockstep --duration 3 --no-realtime \
  --telemetry "$tmp/t.csv" --summary-json "$tmp/s.json" > "$tmp/out.txt" 2> "$tmp/err.txt"
code=$?
[[ $code == 4 ]] || fail "exit $code, expected 4: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "id 9 (lh_ankle): temperature 75 C (fault limit 70 C)" "$tmp/out.txt" "$tmp/err.txt" \
  || fail "no fault naming the servo and its temperature: $(cat "$tmp/out.txt" "$tmp/err.txt")"
/usr/bin/python3 - "$tmp/s.json" "$tmp/t.csv" <<'PY' || fail "summary or telemetry wrong"
import csv, json, math, sys
s = json.load(open(sys.argv[1]))
assert s["exit_code"] == 4, s["exit_code"]
ankle = [d for d in s["devices"] if d["joint"] == "lh_ankle"][0]
assert ankle["faulted"], ankle
assert abs(ankle["readings"]["max_temperature_c"] - 75) < 0.6, ankle["readings"]
for d in s["devices"]:
    h = d["readings"]
    assert h["count"] > 100, h
    assert 35 < h["min_temperature_c"] < 37, h
    assert 11 < h["min_voltage_v"] < 12.1, h
    assert 0.04 < h["peak_current_a"] < 1.0, h
rows = list(csv.reader(open(sys.argv[2])))
assert len(rows[0]) == 25 + 60, len(rows[0])
first = rows[0][1][: -len("_cmd_rad")]
assert rows[0][25:30] == [first + "_temp_c", first + "_current_a", first + "_voltage_v",
                          first + "_torque_nm", first + "_error_bits"], rows[0][25:30]
# The hot servo's column shows the overheat before the run ended.
col = rows[0].index("lh_ankle_temp_c")
assert max(float(r[col]) for r in rows[1:]) >= 74.5
PY

# A bad key is named with its place before anything moves.
sed 's/temperature_fault_c: 70/temperature_fault_c: 50/' "$tmp/robots/hot.yaml" > "$tmp/robots/bad.yaml"
"$animrt" run "$tmp/robots/bad.yaml" --backend sim --lockstep --duration 1 --no-realtime \
  > "$tmp/out2.txt" 2> "$tmp/err2.txt" && fail "a fault limit below the warning was accepted"
grep -Eq "bad.yaml:[0-9]+:[0-9]+: safety.health.temperature_fault_c: expected more than temperature_warn_c \(60\)" \
  "$tmp/err2.txt" "$tmp/out2.txt" || fail "no located error: $(cat "$tmp/err2.txt" "$tmp/out2.txt")"
# A servo's hardware error (its Alert bit) under `error_bits: warn`, its
# bits not read (health off): warned of once, the run plays on (exit 0).
/usr/bin/python3 - "$root/configs/robots/quadruped.yaml" "$tmp/robots/alert.yaml" <<'PY'
import sys
text = open(sys.argv[1]).read()
text = text.replace("  stop_ramp_s: 2.0 ", "  stop_ramp_s: 0.5 \n  health: {error_bits: warn}\n  #", 1)
text = text.replace("  start_ramp_s: 2.0 ", "  start_ramp_s: 0.5 \n  #", 1)
text = text.replace("      return_delay_us: 0 ",
                    "      inject:\n        - {id: 3, at_s: 1.0, hardware_error: 1}\n      return_delay_us: 0 ", 1)
assert "error_bits: warn" in text and "hardware_error" in text
open(sys.argv[2], "w").write(text)
PY
"$animrt" run "$tmp/robots/alert.yaml" --backend sim --lockstep --duration 2 --no-realtime \
  > "$tmp/out3.txt" 2> "$tmp/err3.txt"
code=$?
[[ $code == 0 ]] || fail "error_bits warn: exit $code: $(cat "$tmp/out3.txt" "$tmp/err3.txt")"
[[ $(grep -c "^WARNING bus legs id 3 (lf_ankle): the device reports a hardware error (its error bits are not read)" "$tmp/out3.txt") == 1 ]] \
  || fail "error_bits warn: $(cat "$tmp/out3.txt")"
echo OK
