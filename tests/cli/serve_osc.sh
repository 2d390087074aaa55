#!/usr/bin/env bash
# `animrt serve` on the simulated animatronic figure, triggered over OSC by a
# sender written from the OSC 1.0 specification (osc_send.py): a cue plays,
# malformed packets and unknown addresses are counted and survived, a burst
# of 10,000 cue triggers loses no stop (the figure ramps home), and a stop
# signal (SIGHUP: the terminal went away) stops a served figure as it stops a run.
set -uo pipefail
animrt=$1
root=$2
here=$(dirname "$0")
source "$root/tests/cli/serve.bash"

# Serves until stopped; sets `port` to OSC's once the motion is under way.
start_osc() {
  start_serve "$root/configs/robots/animatronic.yaml" --cues "$root/configs/cues/animatronic.yaml" \
    --backend sim --lockstep --no-realtime --osc-port 0 --no-artnet
  [[ $line =~ ^osc:\ listening\ on\ 127\.0\.0\.1:([0-9]+)$ ]] || fail "no OSC line: '$line'"
  port=${BASH_REMATCH[1]}
}

wait_ended() {
  poll_exit
  kill -0 $pid 2>/dev/null && fail "serve did not end: $(tail -5 "$tmp/err.txt")"
  reap
}

start_osc
# Malformed: no padding, an unknown type tag, an argument missing, an address
# without '/', a bundle element longer than the bundle.
script="send /cue/hello
sleep 1.0
raw 2f73746f70
raw 2f70617573650000 2c780000 00000001
raw 2f70617573650000 2c690000
raw 73746f7000000000 2c000000
raw 2362756e646c6500 0000000000000001 00000190 2f73746f70000000
send /cue/nothere
send /pause i:1
raw 2f70617573650000 2c660000 7fc00000
send /resume
burst 10000 /cue/greet /cue/look_left /cue/hello
sleep 0.2
bundle /cue/sway /stop"
sent=$(/usr/bin/python3 "$here/osc_send.py" "$port" "$script") || fail "the sender failed"
wait_ended
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code, expected 0: $out $(cat "$tmp/err.txt")"
grep -q "ended by stop request" <<<"$out" || fail "not stopped by /stop: $out"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no ramp home and torque off: $(cat "$tmp/err.txt")"
grep -q "TORQUE CUT" <<<"$out" && fail "torque was cut: $out"
# Unknown: /cue/nothere, and a /pause whose argument is NaN.
grep -qE "^osc: $sent packets, [0-9]+ messages, 5 malformed, 2 unknown addresses$" <<<"$out" ||
  fail "expected $sent packets, 5 malformed, 2 unknown: $(grep '^osc:' <<<"$out")"
grep -qE "^cue requests: 10002 posted, [0-9]+ taken" <<<"$out" ||
  fail "expected 10002 cue requests: $(grep '^cue requests' <<<"$out")"
grep -qE "^cues started: sway [1-9][0-9]* hello [1-9]" <<<"$out" ||
  fail "hello never played: $(grep '^cues started' <<<"$out")"
grep -E "^(cues|cue requests|osc:)" <<<"$out"

# A stop signal: the terminal hung up.
start_osc
sleep 0.5
kill -HUP $pid
wait_ended
[[ $code == 0 ]] || fail "SIGHUP: exit $code, expected 0: $(cat "$tmp/out.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "SIGHUP: $(head -3 "$tmp/out.txt")"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "SIGHUP: $(cat "$tmp/err.txt")"
echo "ok: serve over OSC ($sent packets)"
