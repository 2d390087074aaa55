#!/usr/bin/env bash
# animrt run --backend sim: a short real-time run with telemetry and a JSON
# summary; animrt sim: serves the bus on a pty that an independent Protocol
# 2.0 client (pyserial) can ping.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The shipped quadruped with 0.5 s ramps and a stop deadline that leaves the
# walk's wind-down no room (2 s of settling after the ramp), its files made
# absolute: what is checked here is the run's summary and telemetry, not how
# long the figure takes to start and stop (stop_signals stops with the
# shipped wind-down and stop ramp, dashboard_busy_browser runs the shipped
# file unchanged). The shipped watchdog and bus timeout stay.
here=$(cd "$root/configs/robots" && pwd)
robot=$tmp/quadruped.yaml
sed -E -e "s#^(\s*(file|model):\s*)\.\./#\1$here/../#" -e "s#^(\s*(start|stop)_ramp_s:\s*)[0-9.]+#\10.5#" \
  -e "s|^(safety:)$|\1\n  stop_deadline_s: 2.5|" "$here/quadruped.yaml" > "$robot"
grep -q "start_ramp_s: 0.5" "$robot" && grep -q "stop_ramp_s: 0.5" "$robot" &&
  grep -q "^  stop_deadline_s: 2.5$" "$robot" || fail "could not shorten the ramps: $(head -30 "$robot")"

"$animrt" run "$robot" --backend sim --duration 1 --no-realtime \
  --telemetry "$tmp/t.csv" --summary-json "$tmp/s.json" > "$tmp/out.txt" 2> "$tmp/err.txt" \
  || fail "run failed: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^cycles: " "$tmp/out.txt" || fail "no summary: $(cat "$tmp/out.txt")"
grep -q "period: p50" "$tmp/out.txt" || fail "no period line"
/usr/bin/python3 - "$tmp/s.json" "$tmp/t.csv" <<'PY' || fail "summary or telemetry wrong"
import csv, json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "duration", s["end_reason"]
assert s["exit_code"] == 0
assert s["cycles"] > 200, s["cycles"]
assert len(s["joints"]) == 12 and len(s["devices"]) == 12
assert all(not d["faulted"] for d in s["devices"])
rows = list(csv.reader(open(sys.argv[2])))
assert rows[0][0] == "time_s" and len(rows[0]) == 25, rows[0]
assert len(rows) - 1 == s["telemetry"]["records"], (len(rows), s["telemetry"])
PY

"/usr/bin/python3" -c 'import serial' 2> /dev/null \
  || fail "python3-serial not found for /usr/bin/python3 (scripts/install-deps.sh installs it)"
"$animrt" sim "$root/configs/robots/quadruped.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^serial " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $kind == serial && $bus == legs && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"
/usr/bin/python3 - "$pty" <<'PY' || fail "python client could not ping the simulated servo"
import serial, sys

def crc16(data):
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc

def packet(dev, inst, params=b""):
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, dev]) + (len(params) + 3).to_bytes(2, "little") + bytes([inst]) + params
    return body + crc16(body).to_bytes(2, "little")

port = serial.Serial(sys.argv[1], 1000000, timeout=1.0)
port.write(packet(7, 0x01))
reply = port.read(14)
assert len(reply) == 14, reply
assert reply[:5] == bytes([0xFF, 0xFF, 0xFD, 0x00, 7]) and reply[7] == 0x55, reply.hex()
assert crc16(reply[:-2]) == int.from_bytes(reply[-2:], "little"), "bad CRC in reply"
PY
kill -INT $sim_pid
wait $sim_pid || fail "sim did not exit cleanly on SIGINT"
sim_pid=""
echo "run_sim: ok"
