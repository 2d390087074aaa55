#!/usr/bin/env bash
# Every catchable termination signal is a stop request: a run of the
# quadruped on --backend hardware against `animrt sim` that receives it
# mid-motion ramps home, says "deactivate: torque off" and exits 0, and an
# independent Protocol 2.0 client then reads Torque Enable = 0 on all 12
# servos. A second signal (not only a second Ctrl-C) cuts torque (exit 5).
# SIGPIPE stops when stderr's reader has gone, and is ignored otherwise.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
fail() { echo "FAIL: $*"; exit 1; }
source "$root/tests/cli/figure_on_sim.bash"
cat_pid=""
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; [[ -n $cat_pid ]] && kill $cat_pid 2>/dev/null;
      [[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT

start_sim
expect_torque_off "before any run"

# What a signal starts is the same stop request whether the walk winds down
# first or not; the wind-down only adds its two strides to every stop. So
# SIGTERM (systemd's stop) and the second-signal case below stop the walking
# figure as it is, winding its walk down, and every other signal stops a
# copy whose stop deadline leaves the wind-down no room (2 s of settling
# after the 0.5 s ramp): it ramps home at once, as every stop did before
# walks wound down.
walking=$robot
no_wind_down=$tmp/quadruped_no_wind_down.yaml
sed -E "s|^(safety:)$|\1\n  stop_deadline_s: 2.5|" "$walking" > "$no_wind_down"
grep -q "^  stop_deadline_s: 2.5$" "$no_wind_down" || fail "could not set the stop deadline: $(head -30 "$no_wind_down")"

# The motion has started (the start ramp is 0.5 s) when the signal comes.
for sig in HUP INT TERM QUIT USR1 USR2 ALRM VTALRM PROF XCPU XFSZ; do
  robot=$no_wind_down
  [[ $sig == TERM ]] && robot=$walking
  start_figure
  sleep 0.8
  kill -$sig $pid
  wait $pid
  code=$?
  pid=""
  [[ $code == 0 ]] || fail "SIG$sig: exit $code, expected 0: $(cat "$tmp/out.txt" "$tmp/err.txt")"
  grep -q "ended by stop request" "$tmp/out.txt" || fail "SIG$sig: $(head -3 "$tmp/out.txt")"
  grep -q "TORQUE CUT" "$tmp/out.txt" && fail "SIG$sig cut torque: $(head -3 "$tmp/out.txt")"
  grep -q "deactivate: torque off" "$tmp/err.txt" || fail "SIG$sig: $(cat "$tmp/err.txt")"
  expect_torque_off "SIG$sig"
done

robot=$no_wind_down

# SIGPIPE: stderr goes to a reader that leaves (a closed terminal's pipe,
# `2>&1 | head`); the signal is a stop, not a silent death.
mkfifo "$tmp/err.fifo"
: > "$tmp/err.txt"  # the runs above started in it; the reader may not have truncated it yet
cat "$tmp/err.fifo" > "$tmp/err.txt" &
cat_pid=$!
"$animrt" run "$robot" --backend hardware --no-realtime > "$tmp/out.txt" 2> "$tmp/err.fifo" &
pid=$!
for _ in $(seq 200); do
  grep -q "activate: torque on" "$tmp/err.txt" && break
  sleep 0.05
done
grep -q "activate: torque on" "$tmp/err.txt" || fail "SIGPIPE: run did not start"
sleep 0.8
# A SIGPIPE while stdout and stderr still have their readers is a socket's
# or a telemetry pipe's: it leaves the run alone.
kill -PIPE $pid
sleep 0.3
kill -0 $pid 2> /dev/null || fail "SIGPIPE with stderr still read ended the run"
grep -q "ended by" "$tmp/out.txt" && fail "SIGPIPE with stderr still read stopped the run"
kill $cat_pid
wait $cat_pid 2> /dev/null
cat_pid=""
kill -PIPE $pid
wait $pid
code=$?
pid=""
[[ $code == 0 ]] || fail "SIGPIPE: exit $code, expected 0: $(cat "$tmp/out.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "SIGPIPE: $(head -3 "$tmp/out.txt")"
grep -q "TORQUE CUT" "$tmp/out.txt" && fail "SIGPIPE cut torque: $(head -3 "$tmp/out.txt")"
expect_torque_off "SIGPIPE"

# A second signal, of another kind than the first, cuts torque at once,
# here during the walk's wind-down.
robot=$walking
start_figure
sleep 0.8
kill -HUP $pid
sleep 0.1
kill -USR1 $pid
wait $pid
code=$?
pid=""
[[ $code == 5 ]] || fail "SIGHUP, SIGUSR1: exit $code, expected 5: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^TORQUE CUT second stop request" "$tmp/out.txt" || fail "SIGHUP, SIGUSR1: $(head -4 "$tmp/out.txt")"
grep -q "torque switched off at once" "$tmp/err.txt" || fail "SIGHUP, SIGUSR1: $(cat "$tmp/err.txt")"
expect_torque_off "SIGHUP, SIGUSR1"

# animrt sim itself ends cleanly on a stop signal other than Ctrl-C.
kill -HUP $sim_pid
wait $sim_pid
code=$?
sim_pid=""
[[ $code == 0 ]] || fail "animrt sim on SIGHUP: exit $code, expected 0"
echo "stop_every_signal: ok"
