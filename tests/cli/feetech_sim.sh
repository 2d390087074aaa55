#!/usr/bin/env bash
# The STS3215 arm: `animrt run` plays its show on the simulated servos (in
# lockstep), and `animrt sim` serves them on a pty where an independent
# client (pyserial) sends the protocol manual's Ping and Sync Read and gets
# its status packets.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$animrt" run "$root/configs/robots/arm_sts.yaml" --backend sim --duration 1 --lockstep --no-realtime \
  --summary-json "$tmp/s.json" > "$tmp/out.txt" 2>&1 || fail "run failed: $(cat "$tmp/out.txt")"
/usr/bin/python3 - "$tmp/s.json" <<'PY' || fail "summary wrong: $(cat "$tmp/out.txt")"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "duration" and s["exit_code"] == 0, s["end_reason"]
assert len(s["devices"]) == 6 and all(not d["faulted"] for d in s["devices"])
PY

/usr/bin/python3 -c 'import serial' 2> /dev/null \
  || fail "python3-serial not found for /usr/bin/python3 (scripts/install-deps.sh installs it)"
"$animrt" sim "$root/configs/robots/arm_sts.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^serial " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $kind == serial && $bus == arm && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"
/usr/bin/python3 - "$pty" <<'PY' || fail "pyserial client"
import sys, serial
line = serial.Serial(sys.argv[1], 1000000, timeout=1.0)
# Manual example 1: Ping of ID 1, answered FF FF 01 02 00 FC.
line.write(bytes.fromhex("FF FF 01 02 01 FB"))
assert line.read(6) == bytes.fromhex("FF FF 01 02 00 FC")
# Manual example 8: Sync Read of 8 bytes at 0x38 from IDs 1 and 2.
line.write(bytes.fromhex("FF FF FE 06 82 38 08 01 02 36"))
answer = line.read(28)
assert len(answer) == 28, answer.hex(" ")
for packet, servo in ((answer[:14], 1), (answer[14:], 2)):
    assert packet[:5] == bytes([0xFF, 0xFF, servo, 0x0A, 0x00]), packet.hex(" ")
    assert packet[-1] == (~sum(packet[2:-1])) & 0xFF, packet.hex(" ")
PY
echo ok
