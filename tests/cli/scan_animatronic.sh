#!/usr/bin/env bash
# animrt scan of the animatronic figure's three buses as `animrt sim`
# serves them: the neck's two Dynamixel servos at 1 Mbaud (ids 1 and 2),
# the face's Maestro (Get Errors answered, no servo packet sent on its
# line), and the torso's Modbus TCP drive (unit 1; a refused connection is
# one line). Answer timeouts are generous: a busy machine must not hide a
# device. Then an id collision: the quadruped's servos as a box of new
# ones, two plugged in at once, answer as id 1 together, and the scan
# reports a collision at id 1 (and at no other id).
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

start_sim() {
  : > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
  "$animrt" sim "$@" > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
  for _ in $(seq 50); do
    grep -q "^control \|^modbus-tcp " "$tmp/sim.txt" && break
    sleep 0.1
  done
}
start_sim "$root/configs/robots/animatronic.yaml"
neck=$(awk '$1 == "serial" && $2 == "neck" {print $3}' "$tmp/sim.txt")
face=$(awk '$1 == "serial" && $2 == "face" {print $3}' "$tmp/sim.txt")
torso=$(awk '$1 == "modbus-tcp" && $2 == "torso" {print $3}' "$tmp/sim.txt")
[[ -n $neck && -n $face && -n $torso ]] || fail "sim lines: $(cat "$tmp/sim.txt")"

out=$("$animrt" scan "$neck" --timeout-ms 50 --protocol dynamixel2 --baud 57600,1000000 --ids 0-5 2> /dev/null) \
  || fail "neck: $out"
rows=$(awk 'NR > 1 && $2 == "dynamixel2" {print $3 ":" $4}' <<< "$out" | sort | tr '\n' ' ')
[[ $rows == *"1000000:1 1000000:2 "* ]] || fail "neck: $out"

out=$("$animrt" scan "$face" --timeout-ms 100 --baud 115200 --ids 0-3 2> /dev/null) || fail "face: $out"
[[ $(awk 'NR > 1 {print $2, $3}' <<< "$out" | head -1) == "maestro 115200" ]] || fail "face: $out"
[[ $out == *"a Maestro answered, so no servo protocol was tried on it"* ]] || fail "face: $out"
[[ $out != *dynamixel2* && $out != *feetech* ]] || fail "face: servo rows on a Maestro: $out"

out=$("$animrt" scan "tcp://$torso" --timeout-ms 100 --ids 1-8 2> /dev/null) || fail "torso: $out"
[[ $(awk 'NR > 1 {print $2, $4}' <<< "$out") == "modbus-tcp 1" ]] || fail "torso: $out"
out=$("$animrt" scan "tcp://127.0.0.1:1" --ids 1-2 2>&1)
[[ $? -eq 3 && $out == *"error: cannot connect to Modbus TCP 127.0.0.1:1: "* ]] \
  || fail "refused connection: $out"
kill $sim_pid
wait $sim_pid 2> /dev/null
sim_pid=""

# Two new servos on the bus at once: one id, two answers.
start_sim "$root/configs/robots/quadruped.yaml" --factory --control "$tmp/ctl"
pty=$(awk '$1 == "serial" {print $3}' "$tmp/sim.txt")
/usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall(b"plug legs 1\n"); print(s.makefile().readline(), end="")' "$tmp/ctl" > "$tmp/plug.txt"
[[ $(cat "$tmp/plug.txt") == ok* ]] || fail "plug: $(cat "$tmp/plug.txt")"
out=$("$animrt" scan "$pty" --timeout-ms 50 --protocol dynamixel2 --baud 57600 --ids 0-3 2> /dev/null) \
  || fail "collision scan: $out"
[[ $out == *"collision: dynamixel2 id 1 at 57600 baud: "* && $out != *"collision: dynamixel2 id "[02]* ]] \
  || fail "no collision reported: $out"
[[ $(awk -v pty="$pty" '$1 == pty' <<< "$out") == "" ]] || fail "collided id listed: $out"
echo ok
