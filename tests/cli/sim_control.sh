#!/usr/bin/env bash
# animrt sim --control: a hand turns a limp servo through the socket, a
# Protocol 2.0 client (pyserial) reads the new Present Position, and once
# the client switches torque on the hand is refused; the socket is gone
# after Ctrl-C.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
ctl() {  # the tiny client: one command line, prints the reply line
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "$1"
}

"$animrt" sim "$root/configs/robots/quadruped.yaml" --control "$tmp/ctl" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^control " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r _ _ pty < <(grep "^serial " "$tmp/sim.txt")
[[ -S $tmp/ctl ]] || fail "no control socket: $(cat "$tmp/sim.txt")"

[[ $(ctl "hand legs 3 2500") == ok ]] || fail "hand refused"
[[ $(ctl "get legs 3") == "ok ticks=2500 torque=0 id=3 baud=1000000" ]] || fail "get: $(ctl "get legs 3")"
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

port = serial.Serial(sys.argv[1], 1000000, timeout=1.0)
port.write(packet(3, 0x02, bytes([132, 0, 4, 0])))  # Read Present Position
reply = port.read(15)
assert len(reply) == 15 and int.from_bytes(reply[9:13], "little") == 2500, reply.hex()
port.write(packet(3, 0x03, bytes([116, 0]) + (2500).to_bytes(4, "little")))  # Goal Position
assert len(port.read(11)) == 11
port.write(packet(3, 0x03, bytes([64, 0, 1])))  # Torque Enable = 1
assert len(port.read(11)) == 11
PY
[[ $(ctl "hand legs 3 1000") == "error: torque is on" ]] || fail "hand with torque on: $(ctl "hand legs 3 1000")"
[[ $(ctl "get legs 3") == "ok ticks=2500 torque=1 id=3 baud=1000000" ]] || fail "moved with torque on"
kill -INT $sim_pid
wait $sim_pid || fail "sim did not exit cleanly on SIGINT"
sim_pid=""
[[ ! -e $tmp/ctl ]] || fail "control socket left behind"
echo "sim_control: ok"
