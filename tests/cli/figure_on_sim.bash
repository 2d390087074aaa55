# Sourced by the CLI tests that run the quadruped on `--backend hardware`
# against `animrt sim` (a separate process, as real servos would be) and read
# the servos back with an independent client afterwards. Needs $animrt,
# $root, $tmp and fail() from the sourcing script.
#
#   start_sim             serves the quadruped's servos; sets $sim_pid, $pty
#                         and $robot (the robot file with its bus on the pty)
#   start_figure ARGS...  starts `animrt run $robot --backend hardware` and
#                         returns once torque is on; sets $pid
#   torque_enable         prints the 12 servos' Torque Enable, "1=0 2=0 ..."
#   expect_torque_off WHAT  fails unless all 12 read 0

sim_pid=""
pid=""

start_sim() {
  "/usr/bin/python3" -c 'import serial' 2> /dev/null \
    || fail "python3-serial not found for /usr/bin/python3 (scripts/install-deps.sh installs it)"
  : > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
  "$animrt" sim "$root/configs/robots/quadruped.yaml" > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
  for _ in $(seq 50); do
    grep -q "^serial " "$tmp/sim.txt" && break
    sleep 0.1
  done
  local kind bus
  read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
  [[ $kind == serial && $bus == legs && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"
  # The robot file on the pty, its files absolute, short ramps (a quick
  # test) and slack for a busy machine (only what the test does may stop
  # the figure, never a late answer).
  local here
  here=$(cd "$root/configs/robots" && pwd)
  robot="$tmp/quadruped_on_pty.yaml"
  sed -E -e "s|^(\s*port:\s*)\S+|\1$pty|" \
    -e "s#^(\s*(file|model):\s*)\.\./#\1$here/../#" \
    -e "s|^(\s*watchdog_timeout_s:\s*)[0-9.]+|\12.0|" \
    -e "s|^(\s*timeout_ms:\s*)[0-9]+|\120|" \
    -e "s|^(\s*start_ramp_s:\s*)[0-9.]+|\10.5|" \
    -e "s|^(\s*stop_ramp_s:\s*)[0-9.]+|\10.5|" \
    "$here/quadruped.yaml" > "$robot"
  grep -q "port: $pty" "$robot" && grep -q "stop_ramp_s: 0.5" "$robot" \
    || fail "could not put the robot on the pty: $(head -40 "$robot")"
}

start_figure() {
  # Emptied first: the new process may not have truncated them yet when
  # the wait below first looks, and the last run's torque on is in them.
  : > "$tmp/out.txt"
  : > "$tmp/err.txt"
  "$animrt" run "$robot" --backend hardware --no-realtime "$@" > "$tmp/out.txt" 2> "$tmp/err.txt" &
  pid=$!
  for _ in $(seq 200); do
    grep -q "activate: torque on" "$tmp/err.txt" && return 0
    kill -0 $pid 2> /dev/null || break
    sleep 0.05
  done
  fail "run did not start: $(cat "$tmp/out.txt" "$tmp/err.txt")"
}

# "ID=TORQUE_ENABLE ..." of servos 1-12, read by the independent client.
torque_enable() {
  local probe
  probe=$(/usr/bin/python3 "$root/tests/cli/dxl_probe.py" "$pty" 1 12 0 2>&1) || {
    echo "$probe"
    return 1
  }
  awk '{printf "%s%s=%s", (NR > 1 ? " " : ""), $1, $3} END {print ""}' <<< "$probe"
}

expect_torque_off() {
  local values
  values=$(torque_enable) || fail "$1: reading Torque Enable back: $values"
  [[ $values == "1=0 2=0 3=0 4=0 5=0 6=0 7=0 8=0 9=0 10=0 11=0 12=0" ]] ||
    fail "$1: Torque Enable read back from the servos: $values"
}
