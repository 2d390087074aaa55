#!/usr/bin/env bash
# Time from `kill -9` of `animrt run --backend hardware` to every simulated
# actuator stopped by its device-side watchdog, per protocol.
#
# Usage: bench/kill9_watchdog.sh ANIMRT [TRIALS]
# For each delay d after the kill, TRIALS runs are killed 0.5 s after
# activation; an independent client then asks each device, once, whether its
# guard fired (Dynamixel: Bus Watchdog 98 reads 255; Maestro: Get Errors has
# the serial timeout bit). A question asked before the guard fired feeds it,
# as any instruction would, so each trial asks once. Prints, per delay, in
# how many trials every device had fired.
set -uo pipefail
animrt=$1
trials=${2:-5}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill -KILL $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT

start_sim() {
  "$animrt" sim "$root/configs/robots/$1.yaml" > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
  for _ in $(seq 50); do
    grep -q "^serial " "$tmp/sim.txt" && break
    sleep 0.1
  done
  sleep 0.2
}
stop_sim() {
  kill -INT $sim_pid
  wait $sim_pid
  sim_pid=""
}
# Kills a run $2 s after activation, waits $1 s, then runs the probe ($3...).
trial() {
  local delay=$1 after=$2
  shift 2
  "$animrt" run "$tmp/robot.yaml" --backend hardware > /dev/null 2> "$tmp/err.txt" &
  local pid=$!
  for _ in $(seq 100); do
    grep -q "activate: torque on" "$tmp/err.txt" && break
    sleep 0.05
  done
  sleep "$after"
  /usr/bin/python3 - "$delay" "$pid" "$@" <<'PY'
import os, signal, sys, time, serial

def crc16(data):
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc

def read98(port, dev):
    body = bytes([0xFF, 0xFF, 0xFD, 0x00, dev, 7, 0, 0x02, 98, 0, 1, 0])
    port.write(body + crc16(body).to_bytes(2, "little"))
    reply = port.read(12)
    return reply[9] if len(reply) == 12 else -1

delay, pid, kind, path = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
port = serial.Serial(path, 1000000 if kind == "dxl" else 115200, timeout=0.5)
try:
    os.kill(pid, signal.SIGKILL)
except ProcessLookupError:
    raise SystemExit(0)
t0 = time.monotonic()
while time.monotonic() - t0 < delay:
    pass
# Answers to the killed run's last request may still wait in the line.
port.reset_input_buffer()
if kind == "dxl":
    fired = [read98(port, dev) == 255 for dev in range(1, int(sys.argv[5]) + 1)]
else:
    port.write(bytes([0xA1]))
    fired = [bool(int.from_bytes(port.read(2), "little") & 0x20)]
print(1 if all(fired) else 0)
PY
  wait $pid 2> /dev/null
}

# Counts one trial's answer: 1 (every device fired), 0, or nothing (the run
# had ended before the kill: its stderr is kept in ended-*.txt).
tally() {
  case $1 in
    1) n=$((n + 1)) ;;
    0) ;;
    *)
      ended=$((ended + 1))
      cp "$tmp/err.txt" "$keep/ended-$ended.txt"
      ;;
  esac
  lost=""
  [[ $ended -gt 0 ]] && lost=" ($ended of them ended before the kill, see $keep)"
}
keep=${KEEP_DIR:-/tmp/kill9_watchdog}
mkdir -p "$keep"

# The shipped robot, its ports pointed at the simulator.
robot() {
  sed -e "s#\.\./#$root/configs/#g" "$root/configs/robots/$1.yaml" > "$tmp/robot.yaml"
  while read -r kind bus where; do
    # Each bus's port line follows its name; replace the first after it.
    sed -i "/^  $bus:/,/port:/ s#port: [^ ]*#port: $where#" "$tmp/robot.yaml"
  done < <(grep -E "^(serial|modbus-tcp) " "$tmp/sim.txt")
}

echo "commit $(git -C "$root" rev-parse --short HEAD), $trials trials per delay"
start_sim quadruped
robot quadruped
pty=$(awk '$2 == "legs" {print $3}' "$tmp/sim.txt")
for delay in 0.085 0.090 0.095 0.100 0.105 0.110; do
  n=0 ended=0
  for _ in $(seq "$trials"); do tally "$(trial $delay 0.5 dxl "$pty" 12)"; done
  echo "dynamixel2 (quadruped, 12 servos, Bus Watchdog 100 ms): ${delay} s after kill -9: all stopped in $n of $trials$lost"
done
stop_sim

start_sim animatronic
robot animatronic
pty=$(awk '$2 == "face" {print $3}' "$tmp/sim.txt")
for delay in 0.085 0.090 0.095 0.100 0.105 0.110; do
  n=0 ended=0
  for _ in $(seq "$trials"); do tally "$(trial $delay 0.5 maestro "$pty")"; done
  echo "maestro (animatronic face, serial timeout 100 ms): ${delay} s after kill -9: timed out in $n of $trials$lost"
done
stop_sim
