#!/usr/bin/env bash
# kill -9 of a served figure (`animrt serve --backend hardware` against
# `animrt sim`): a figure in service keeps the devices' own guards of a run,
# so every servo's Bus Watchdog fires and it holds where it stopped.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
serve_pid=""
trap '[[ -n $serve_pid ]] && kill -KILL $serve_pid 2>/dev/null; [[ -n $sim_pid ]] && kill -KILL $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

/usr/bin/python3 -c 'import serial' 2> /dev/null || fail "python3-serial not found for /usr/bin/python3"
"$animrt" sim "$root/configs/robots/head.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^serial " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $kind == serial && $bus == neck && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"
# The shipped head, its port at the simulator's pty, patient answer timeouts
# and a runtime watchdog of 2 s (the simulator shares a busy machine; the
# servos' own Bus Watchdog is what is under test).
sed -e "s#port: /dev/ttyUSB0#port: $pty#" -e "s#\.\./#$root/configs/#g" \
  -e 's#timeout_ms: [0-9]*#timeout_ms: 40#' \
  -e 's#watchdog_timeout_s: [0-9.]*#watchdog_timeout_s: 2.0#' "$root/configs/robots/head.yaml" > "$tmp/robot.yaml"
grep -q "watchdog_timeout_s: 2.0" "$tmp/robot.yaml" || fail "could not widen the watchdog: $(head -30 "$tmp/robot.yaml")"

"$animrt" serve "$tmp/robot.yaml" --cues "$root/configs/cues/head.yaml" --backend hardware \
  --no-realtime --no-osc > "$tmp/out.txt" 2> "$tmp/err.txt" &
serve_pid=$!
for _ in $(seq 100); do
  grep -q "activate: torque on" "$tmp/err.txt" && break
  sleep 0.1
done
grep -q "activate: torque on" "$tmp/err.txt" || fail "serve did not start: $(cat "$tmp/err.txt")"
sleep 1.0
kill -0 $serve_pid 2> /dev/null || fail "serve ended before the kill: $(cat "$tmp/out.txt" "$tmp/err.txt")"
kill -KILL $serve_pid
wait $serve_pid 2> /dev/null
serve_pid=""
sleep 0.3
/usr/bin/python3 "$root/tests/cli/dxl_probe.py" "$pty" 1 4 0.2 > "$tmp/probe.txt" ||
  fail "probe: $(cat "$tmp/probe.txt")"
[[ $(wc -l < "$tmp/probe.txt") -eq 4 ]] || fail "probe: $(cat "$tmp/probe.txt")"
while read -r id watchdog torque moving p1 p2; do
  [[ $watchdog == 255 ]] || fail "id $id: Bus Watchdog reads $watchdog after kill -9, expected 255"
  [[ $torque == 1 ]] || fail "id $id: torque $torque, expected 1 (held where it stopped)"
  [[ $moving == 0 ]] || fail "id $id: still moving after kill -9"
  [[ $p1 == "$p2" ]] || fail "id $id: position went from $p1 to $p2 after kill -9"
done < "$tmp/probe.txt"
echo "ok: a served figure's servos stop by their own watchdog"
