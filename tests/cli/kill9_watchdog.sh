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
# resolved against the shipped folder), with answer timeouts of 40 ms and
# the runtime's watchdog at 2 s: the simulator shares this machine with
# whatever else runs, and a configure that gives up on a late answer, or
# servos faulted and switched off because the simulator was held up 0.1 s,
# would end the test before it began. What is under test is the servos'
# own Bus Watchdog (its default, 100 ms), which neither widens.
# Its stop ramp is 0.5 s: the first run dies by kill -9 and the second is
# stopped to see it end cleanly, neither for the ramp's length.
patient='s#timeout_ms: [0-9]*#timeout_ms: 40#'
sed -e "s#port: /dev/ttyUSB0#port: $pty#" -e "s#\.\./#$root/configs/#g" -e "$patient" \
  -e "s#watchdog_timeout_s: [0-9.]*#watchdog_timeout_s: 2.0#" \
  -e "s#stop_ramp_s: [0-9.]*#stop_ramp_s: 0.5#" "$root/configs/robots/quadruped.yaml" > "$tmp/robot.yaml"
grep -q "stop_ramp_s: 0.5" "$tmp/robot.yaml" || fail "could not shorten the stop ramp: $(head -30 "$tmp/robot.yaml")"
grep -q "watchdog_timeout_s: 2.0" "$tmp/robot.yaml" || fail "could not widen the watchdog: $(head -30 "$tmp/robot.yaml")"

# The last run's output is emptied first: the new process may not have
# opened (and truncated) it yet when the wait below first looks, and the
# last run's torque on is in it.
start_run() {
  : > "$tmp/out.txt"
  : > "$tmp/err.txt"
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
kill -0 $run_pid 2> /dev/null || fail "the run ended before the kill: $(cat "$tmp/out.txt" "$tmp/err.txt")"
kill -KILL $run_pid
wait $run_pid 2> /dev/null
run_pid=""
# The default watchdog here is 100 ms (5 periods of 200 Hz are 25 ms; at
# least 100 ms; units of 20 ms). 0.3 s is plenty, and short of any servo
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

# The animatronic figure: Dynamixel neck, Maestro face (its serial timeout is
# a setting of the board; the simulated board holds what the robot file
# says), Modbus torso (no guard: validate says so).
: > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
"$animrt" sim "$root/configs/robots/animatronic.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  [[ $(grep -c "^serial \|^modbus-tcp " "$tmp/sim.txt") -eq 3 ]] && break
  sleep 0.1
done
neck=$(awk '$1 == "serial" && $2 == "neck" {print $3}' "$tmp/sim.txt")
face=$(awk '$1 == "serial" && $2 == "face" {print $3}' "$tmp/sim.txt")
torso=$(awk '$1 == "modbus-tcp" && $2 == "torso" {print $3}' "$tmp/sim.txt")
[[ $neck == /dev/pts/* && $face == /dev/pts/* && -n $torso ]] || fail "sim lines: $(cat "$tmp/sim.txt")"
sed -e "s#port: /dev/ttyUSB0#port: $neck#" -e "s#port: /dev/ttyACM0#port: $face#" \
  -e "s#port: 192.168.1.50:502#port: $torso#" -e "s#\.\./#$root/configs/#g" -e "$patient" \
  "$root/configs/robots/animatronic.yaml" > "$tmp/robot.yaml"
start_run
sleep 1.0
kill -0 $run_pid 2> /dev/null || fail "the run ended before the kill: $(cat "$tmp/out.txt" "$tmp/err.txt")"
kill -KILL $run_pid
wait $run_pid 2> /dev/null
run_pid=""
sleep 0.3  # watchdogs: 100 ms (neck and face)
/usr/bin/python3 "$root/tests/cli/dxl_probe.py" "$neck" 1 2 0.2 > "$tmp/probe.txt" ||
  fail "probe: $(cat "$tmp/probe.txt")"
while read -r id watchdog torque moving p1 p2; do
  [[ $watchdog == 255 && $moving == 0 && $p1 == "$p2" ]] ||
    fail "neck id $id after kill -9: watchdog $watchdog, moving $moving, position $p1 then $p2"
done < "$tmp/probe.txt"
# The Maestro, in its compact protocol: Get Errors (0xA1) shows the serial
# timeout (bit 5); Get Position (0x90) of each face channel reads 0: the
# board sent them home, which is off (limp) on a board with factory settings.
/usr/bin/python3 - "$face" <<'PY' || fail "the Maestro did not time out after kill -9"
import serial, sys
port = serial.Serial(sys.argv[1], 115200, timeout=0.5)
port.write(bytes([0xA1]))
errors = int.from_bytes(port.read(2), "little")
assert errors & 0x20, "errors 0x%04x: no serial timeout" % errors
for channel in (0, 1, 2):
    port.write(bytes([0x90, channel]))
    answer = port.read(2)
    assert len(answer) == 2, "no answer for channel %d" % channel
    assert int.from_bytes(answer, "little") == 0, "channel %d still pulses: %r" % (channel, answer)
PY
kill -INT $sim_pid
wait $sim_pid || fail "sim did not exit cleanly on SIGINT"
sim_pid=""
echo "kill9_watchdog: ok"
