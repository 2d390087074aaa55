#!/usr/bin/env bash
# animrt sim --factory --state: new servos start as ID 1 at 57600 baud (and
# hear nothing at 1 Mbaud) with only the first one plugged in; an ID given
# to it is in the state file and is still there after a restart.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
ctl() {
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "$1"
}
start_sim() {
  : > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
  "$animrt" sim "$root/configs/robots/quadruped.yaml" --factory --state "$tmp/state" \
    --control "$tmp/ctl" > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
  for _ in $(seq 50); do
    grep -q "^control " "$tmp/sim.txt" && break
    sleep 0.1
  done
  read -r _ _ pty < <(grep "^serial " "$tmp/sim.txt")
  [[ -S $tmp/ctl ]] || fail "sim did not start: $(cat "$tmp/sim.txt")"
}
stop_sim() {
  kill -INT $sim_pid
  wait $sim_pid || fail "sim did not exit cleanly"
  sim_pid=""
}

start_sim
[[ $(ctl "get legs 5") == *" torque=0 id=1 baud=57600" ]] || fail "not factory: $(ctl "get legs 5")"
/usr/bin/python3 - "$pty" <<'PY' || fail "pyserial client"
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

fast = serial.Serial(sys.argv[1], 1000000, timeout=0.3)
fast.write(packet(1, 0x01))  # a new servo does not hear 1 Mbaud
assert fast.read(14) == b""
fast.close()
# Reads return once their answer is in: the long timeout is for a loaded machine.
port = serial.Serial(sys.argv[1], 57600, timeout=5)
port.write(packet(0xFE, 0x01))  # broadcast ping: one new servo plugged in
assert len(port.read(14)) == 14
port.timeout = 0.3
assert port.read(14) == b""  # and only one
port.timeout = 5
port.write(packet(1, 0x03, bytes([7, 0, 1])))  # Write ID = 1 ... to 1 (nothing changes)
assert len(port.read(11)) == 11
port.write(packet(1, 0x03, bytes([7, 0, 21])))  # ID = 21
reply = port.read(11)
assert len(reply) == 11 and reply[4] == 21, reply.hex()
PY
[[ $(ctl "get legs 1") == *" id=21 baud=57600" ]] || fail "id not set: $(ctl "get legs 1")"
[[ $(ctl "plug legs 1") == ok ]] || fail "plug"
stop_sim
[[ $(grep -c '^legs ' "$tmp/state") == 12 ]] || fail "state file: $(cat "$tmp/state")"

start_sim
[[ $(ctl "get legs 1") == *" id=21 baud=57600" ]] || fail "id not kept: $(ctl "get legs 1")"
[[ $(ctl "get legs 2") == *" id=1 baud=57600" ]] || fail "second servo: $(ctl "get legs 2")"
stop_sim
echo "sim_factory_state: ok"
