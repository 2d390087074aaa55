#!/usr/bin/env bash
# animrt calibrate on a multi-turn joint (Dynamixel extended position mode):
# configure puts its servo in Operating Mode 4, the hand turns it through
# several turns and leaves it at home, calibrate writes the servo's Homing
# Offset so that home reads the file's zero_ticks (also after a power
# cycle, which restarts the servo's count of turns) and the limits within
# 1 deg of what was moved, every other byte of the file kept. Then a servo
# left in current-based position mode (as a process killed during a
# compliant hold leaves it) is put back in its mode by the next run, with
# one line, and the run plays.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
fail() { echo "FAIL: $*"; exit 1; }
trap 'stop_sim; rm -rf "$tmp"' EXIT
source "$root/tests/cli/commission_sim.bash"

copy_robot quadruped
robot=$tmp/robots/quadruped.yaml
# lf_knee geared 4:1 behind a multi-turn servo: 16384 servo ticks per joint turn.
/usr/bin/python3 - "$robot" <<'PY'
import sys
p = sys.argv[1]
s = open(p).read()
old = "actuator: {bus: legs, id: 2, ticks_per_rev: 4096, zero_ticks: 2048, direction: 1}"
new = "actuator: {bus: legs, id: 2, ticks_per_rev: 16384, zero_ticks: 2048, direction: 1, multi_turn: true}"
assert old in s
s = s.replace(old, new)
s = s.replace("  lf_knee:\n    limits: {min_deg: -60, max_deg: 60,", "  lf_knee:  # geared 4:1\n    limits: {min_deg: -200, max_deg: 200,")
open(p, "w").write(s)
PY
"$animrt" validate "$robot" > /dev/null || fail "the multi-turn robot does not load"
cp "$robot" "$tmp/original.yaml"
start_sim "$robot"

# The hand: up 3.5 turns of the servo, down 1.2 turns below the start, then
# home 1.7 turns up; in steps of up to 3000 ticks (more than half a turn, so
# a calibrate that unwrapped them as one turn's would get the range wrong).
# The simulator's hand path takes each step after the servo has answered 5
# reads of its position, so calibrate sees every step whatever the load
# (the path is done after 60 reads: the first step at once, then 12 of 5;
# --seconds-per-joint 5.0 is some 1000 reads at 200 Hz). On a loaded
# machine the Homing Offset's reads are retried: a retried read's later
# answer must not pass for the next read's (serial_servo_core_test,
# DynamixelBusLateAnswers).
steps='3000 6000 9000 12000 16384 13000 8000 4000 0 -2867 0 3000 6963'
/usr/bin/python3 - "$tmp/ctl" "$steps" "$tmp/out.txt" "$animrt" calibrate "$robot" --port "legs=$pty" \
  --non-interactive --seconds-per-joint 5.0 --joint lf_knee <<'PY'
import socket, subprocess, sys
ctl, steps, out = sys.argv[1], sys.argv[2], sys.argv[3]
proc = subprocess.Popen(sys.argv[4:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
log = []
for line in proc.stdout:
    log.append(line)
    if line.startswith("lf_knee: move it"):
        s = socket.socket(socket.AF_UNIX); s.connect(ctl)
        s.sendall(f"hand-path legs 2 5 {steps}\n".encode())
        reply = s.makefile().readline()
        assert reply.startswith("ok"), reply
proc.wait()
open(out, "w").write("".join(log))
sys.exit(proc.returncode)
PY
[[ $? -eq 0 ]] || fail "calibrate failed: $(cat "$tmp/out.txt")"
grep -q "id 2 (lf_knee) was in Operating Mode 3 (position), set to 4 (extended position)" \
  "$tmp/out.txt" || fail "no Operating Mode line: $(cat "$tmp/out.txt")"
grep -q "lf_knee: Homing Offset set: its home reads 2048 ticks" "$tmp/out.txt" ||
  fail "no homing line: $(cat "$tmp/out.txt")"
"$animrt" validate "$robot" > /dev/null || fail "the calibrated file does not load"

reads() { ctl "get legs 2" | sed -n 's/.*ticks=\(-\?[0-9]*\).*/\1/p'; }
home=$(reads)
(( home >= 2047 && home <= 2049 )) || fail "home reads $home, not the file's 2048"
# A power cycle restarts the servo's count from the shaft's angle: home still reads 2048.
ctl "unplug legs 1" > /dev/null
ctl "plug legs 1" > /dev/null
home=$(reads)
(( home >= 2047 && home <= 2049 )) || fail "after a power cycle home reads $home"

/usr/bin/python3 - "$tmp/original.yaml" "$robot" <<'PY' || fail "calibrated values or layout"
import re, sys
old = open(sys.argv[1]).read().split("\n")
new = open(sys.argv[2]).read().split("\n")
assert len(old) == len(new), "line count changed"
start = next(i for i, l in enumerate(new) if l.startswith("  lf_knee:"))
mask = lambda s: re.sub(r"\b(min_deg|max_deg|zero_ticks|direction|home_deg): -?[0-9.]+", r"\1: X", s)
for i, (a, b) in enumerate(zip(old, new)):
    if a != b:
        assert start < i <= start + 3, f"line {i+1} changed outside lf_knee:\n{a}\n{b}"
        assert mask(a) == mask(b), f"line {i+1} changed beyond its values:\n{a}\n{b}"
block = "\n".join(new[start:start + 4])
num = lambda key: float(re.search(key + r": (-?[0-9.]+)", block).group(1))
# Seen from home (6963): up to 16384, down to -2867; 16384 servo ticks per joint turn.
lo, hi = (-2867 - 6963) * 360 / 16384, (16384 - 6963) * 360 / 16384
assert abs(num("min_deg") - lo) <= 1 and abs(num("max_deg") - hi) <= 1, (block, lo, hi)
assert num("zero_ticks") == 2048 and num("direction") == 1 and num("home_deg") == 0, block
assert "multi_turn: true" in block and "# geared 4:1" in block, block
PY

# A run killed during a compliant hold leaves lf_hip's servo (id 1) in
# current-based position mode, kept in EEPROM.
"$animrt" servo "$pty" --protocol dynamixel2 --id 1 --baud 1000000 set-mode current-position \
  > "$tmp/mode.txt" 2>&1 || fail "set-mode: $(cat "$tmp/mode.txt")"
# The next run on them (--backend hardware against the simulator's pty),
# with a stop deadline that leaves the walk's wind-down no room: the run
# is here for its configure.
sed -E -e "s|^(\s*port:\s*)\S+|\1$pty|" -e "s|^(\s*watchdog_timeout_s:\s*)[0-9.]+|\12.0|" \
  -e "s|^(\s*timeout_ms:\s*)[0-9]+|\120|" -e "s#^(\s*(start|stop)_ramp_s:\s*)[0-9.]+#\10.3#" \
  -e "s|^(safety:)$|\1\n  stop_deadline_s: 2.3|" "$robot" > "$tmp/robots/run.yaml"
grep -q "^  stop_deadline_s: 2.3$" "$tmp/robots/run.yaml" || fail "could not set the stop deadline"
"$animrt" run "$tmp/robots/run.yaml" --backend hardware --no-realtime --duration 0.5 \
  > "$tmp/run.txt" 2>&1 || fail "run: $(cat "$tmp/run.txt")"
grep -q "id 1 (lf_hip) was in Operating Mode 5 (current-based position), set to 3 (position)" \
  "$tmp/run.txt" || fail "no Operating Mode line: $(cat "$tmp/run.txt")"
[[ $(grep -c "was in Operating Mode" "$tmp/run.txt") -eq 1 ]] ||
  fail "other servos' modes changed: $(cat "$tmp/run.txt")"
# Read back by an independent client: Operating Mode (11) of servo 1 is 3 again.
mode=$(/usr/bin/python3 - "$pty" <<'PY'
import sys, serial
def crc16(data):
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc
port = serial.Serial(sys.argv[1], 1000000, timeout=0.5)
body = bytes([0xFF, 0xFF, 0xFD, 0x00, 1, 7, 0, 0x02, 11, 0, 1, 0])
port.write(body + crc16(body).to_bytes(2, "little"))
reply = port.read(12)
assert len(reply) == 12 and reply[8] == 0, reply.hex()
print(reply[9])
PY
) || fail "reading Operating Mode back: $mode"
[[ $mode == 3 ]] || fail "servo 1 Operating Mode $mode after the run"
echo "calibrate_multiturn: ok"
