#!/usr/bin/env bash
# kill -9 of a run on --backend hardware against `animrt sim`: nothing in the
# process can react, so the servos must stop by themselves. Read with an
# independent Protocol 2.0 client after the Bus Watchdog's time plus a margin:
# every servo's watchdog fired (98 reads 255), it is not moving, its position
# holds, and its torque is still on (it holds where it stopped). The next run
# recovers the watchdogs at configure and says so.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
run_pid=""
trap '[[ -n $run_pid ]] && kill -KILL $run_pid 2>/dev/null; [[ -n $sim_pid ]] && kill -KILL $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

/usr/bin/python3 -c 'import serial' 2> /dev/null \
  || fail "python3-serial not found for /usr/bin/python3 (scripts/install-deps.sh installs it)"
"$animrt" sim "$root/configs/robots/quadruped.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^serial " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $kind == serial && $bus == legs && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"

# The shipped robot, its port pointed at the simulator's pty (files it names
# resolved against the shipped folder).
sed -e "s#port: /dev/ttyUSB0#port: $pty#" -e "s#\.\./#$root/configs/#g" \
  "$root/configs/robots/quadruped.yaml" > "$tmp/robot.yaml"

start_run() {
  "$animrt" run "$tmp/robot.yaml" --backend hardware --no-realtime > "$tmp/out.txt" 2> "$tmp/err.txt" &
  run_pid=$!
  for _ in $(seq 100); do
    grep -q "activate: torque on" "$tmp/err.txt" && break
    sleep 0.1
  done
  grep -q "activate: torque on" "$tmp/err.txt" || fail "run did not start: $(cat "$tmp/err.txt")"
}

start_run
sleep 1.0  # mid start ramp: every joint on its way
kill -KILL $run_pid
wait $run_pid 2> /dev/null
run_pid=""
# The default watchdog here is 60 ms (5 periods of 200 Hz are 25 ms; at
# least 50 ms; units of 20 ms). 0.3 s is plenty, and short of any servo
# reaching its goal by itself.
sleep 0.3
/usr/bin/python3 "$root/tests/cli/dxl_probe.py" "$pty" 1 12 0.2 > "$tmp/probe.txt" ||
  fail "probe: $(cat "$tmp/probe.txt")"
[[ $(wc -l < "$tmp/probe.txt") -eq 12 ]] || fail "probe: $(cat "$tmp/probe.txt")"
while read -r id watchdog torque moving p1 p2; do
  [[ $watchdog == 255 ]] || fail "id $id: Bus Watchdog reads $watchdog after kill -9, expected 255 (fired)"
  [[ $torque == 1 ]] || fail "id $id: torque $torque, expected 1 (held where it stopped)"
  [[ $moving == 0 ]] || fail "id $id: still moving after kill -9"
  [[ $p1 == "$p2" ]] || fail "id $id: position went from $p1 to $p2 after kill -9"
done < "$tmp/probe.txt"

# The next run clears the fired watchdogs at configure, says so, and runs.
start_run
grep -q "Bus Watchdog had fired on id 1 (lf_hip)" "$tmp/err.txt" ||
  fail "no warning about the fired watchdogs: $(cat "$tmp/err.txt")"
kill -INT $run_pid
wait $run_pid
code=$?
run_pid=""
[[ $code == 0 ]] || fail "second run: exit $code: $(cat "$tmp/out.txt" "$tmp/err.txt")"
# A clean stop leaves no watchdog armed.
/usr/bin/python3 "$root/tests/cli/dxl_probe.py" "$pty" 1 12 0 > "$tmp/probe.txt" ||
  fail "probe: $(cat "$tmp/probe.txt")"
while read -r id watchdog torque moving p1 p2; do
  [[ $watchdog == 0 && $torque == 0 ]] || fail "id $id after a clean stop: watchdog $watchdog, torque $torque"
done < "$tmp/probe.txt"

kill -INT $sim_pid
wait $sim_pid || fail "sim did not exit cleanly on SIGINT"
sim_pid=""
echo "kill9_watchdog: ok"
