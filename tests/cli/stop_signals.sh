#!/usr/bin/env bash
# Ctrl-C on a run of the simulated quadruped: the first SIGINT winds the walk
# down, ramps home and exits 0; a second one switches torque off at once and
# exits 5, saying so. A stop from the dashboard is not a first Ctrl-C: one
# SIGINT during its stop (the wind-down, then the ramp) leaves it to finish.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The shipped quadruped with a short start ramp (its files made absolute):
# the motion is under way sooner. The stop stays as shipped (the walk's
# wind-down, then a 2 s ramp), so a second signal 0.3 s into it still finds
# it running. Slack for a busy
# machine, as in figure_on_sim.bash: only a signal may end these runs,
# never a late answer.
here=$(cd "$root/configs/robots" && pwd)
robot=$tmp/quadruped.yaml
sed -E -e "s#^(\s*(file|model):\s*)\.\./#\1$here/../#" \
  -e "s|^(\s*start_ramp_s:\s*)[0-9.]+|\10.5|" \
  -e "s|^(\s*watchdog_timeout_s:\s*)[0-9.]+|\12.0|" -e "s|^(\s*timeout_ms:\s*)[0-9]+|\120|" \
  "$here/quadruped.yaml" > "$robot"
grep -q "start_ramp_s: 0.5" "$robot" && grep -q "stop_ramp_s: 2.0" "$robot" &&
  grep -q "watchdog_timeout_s: 2.0" "$robot" ||
  fail "could not shorten the start ramp: $(grep -E 'ramp|watchdog' "$robot")"

# Starts a run until Ctrl-C and waits until its motion is under way. The
# last run's output is emptied first: the new process may not have opened
# (and truncated) it yet when the wait below first looks.
start_run() {
  : > "$tmp/out.txt"
  : > "$tmp/err.txt"
  "$animrt" run "$robot" --backend sim --no-realtime "${@:2}" \
    > "$tmp/out.txt" 2> "$tmp/err.txt" &
  pid=$!
  for _ in $(seq 100); do
    grep -q "activate: torque on" "$tmp/err.txt" && break
    sleep 0.1
  done
  grep -q "activate: torque on" "$tmp/err.txt" || fail "run did not start: $(cat "$tmp/err.txt")"
  sleep "$1"
}

start_run 0.8
kill -INT $pid
wait $pid
code=$?
pid=""
[[ $code == 0 ]] || fail "one SIGINT: exit $code, expected 0: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "one SIGINT: $(head -3 "$tmp/out.txt")"
grep -q "TORQUE CUT" "$tmp/out.txt" && fail "one SIGINT cut torque: $(head -3 "$tmp/out.txt")"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "one SIGINT: $(cat "$tmp/err.txt")"

start_run 0.8
kill -INT $pid
sleep 0.3
kill -INT $pid
wait $pid
code=$?
pid=""
[[ $code == 5 ]] || fail "two SIGINTs: exit $code, expected 5: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^TORQUE CUT second stop request" "$tmp/out.txt" || fail "two SIGINTs: $(head -4 "$tmp/out.txt")"
grep -q "torque switched off at once" "$tmp/err.txt" || fail "two SIGINTs: $(cat "$tmp/err.txt")"
start_run 0.8 --dashboard 127.0.0.1:0
line=$(head -n 1 "$tmp/out.txt")
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "no dashboard line: '$line'"
/usr/bin/python3 - "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" <<'PY' || fail "the dashboard's stop was refused"
import sys, urllib.request
req = urllib.request.Request(sys.argv[1] + "/api/stop", data=b"{}", method="POST")
req.add_header("Authorization", "Bearer " + sys.argv[2])
assert urllib.request.urlopen(req).status == 200
PY
sleep 0.3
kill -INT $pid
wait $pid
code=$?
pid=""
[[ $code == 0 ]] || fail "dashboard stop, then one SIGINT: exit $code, expected 0: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "TORQUE CUT" "$tmp/out.txt" && fail "dashboard stop, then one SIGINT cut torque: $(head -4 "$tmp/out.txt")"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "dashboard stop, then one SIGINT: $(cat "$tmp/err.txt")"
echo "stop_signals: ok"
