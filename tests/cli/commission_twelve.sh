#!/usr/bin/env bash
# A box of 12 factory-new Dynamixel servos (animrt sim --factory: all id 1
# at 57600 baud, only the first plugged in) commissioned one at a time as
# docs/cli.md says: each new servo is found by the scan as id 1 at 57600,
# `animrt servo` gives it its id and 1 Mbaud, and the next scan finds it
# there. The last scan lists all twelve at 1 Mbaud, and the state file
# keeps what was set.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
# The simulator saves its state file as it ends: waited for before its folder goes.
trap '[[ -n $sim_pid ]] && { kill $sim_pid 2>/dev/null; wait $sim_pid 2>/dev/null; }; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
ctl() {
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "$1"
}

"$animrt" sim "$root/configs/robots/quadruped.yaml" --factory --state "$tmp/state" \
  --control "$tmp/ctl" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^control " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r _ _ pty < <(grep "^serial " "$tmp/sim.txt")
[[ -S $tmp/ctl && $pty == /dev/pts/* ]] || fail "sim did not start: $(cat "$tmp/sim.txt")"

# "BAUD:ID" of every servo a scan at BAUD finds, sorted.
found() {
  "$animrt" scan "$pty" --timeout-ms 30 --protocol dynamixel2 --baud "$1" --ids 0-14 > "$tmp/scan.txt" \
    2> "$tmp/progress.txt" || fail "scan: $(cat "$tmp/scan.txt" "$tmp/progress.txt")"
  grep -q "^collision" "$tmp/scan.txt" && fail "collision with one new servo: $(cat "$tmp/scan.txt")"
  awk 'NR > 1 && $2 == "dynamixel2" {print $3 ":" $4}' "$tmp/scan.txt" | sort | tr '\n' ' '
}

# Refused before anything is written, the new servo left as it was: a rate
# the line cannot be set to (a pty takes only the standard rates: the servo
# would be stranded there), an empty id (it was read as 0), and a second
# servo answering as the same id.
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 1 set-baud 4500000 2>&1)
[[ $? -eq 3 && $out == *"cannot be set to 4500000 baud"*"nothing was written"* ]] \
  || fail "set-baud to a rate the pty cannot take: $out"
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 1 set-id "" 2>&1)
[[ $? -eq 1 && $out == *'Value "" is not a whole number'* ]] || fail "set-id \"\": $out"
[[ $(ctl "plug legs 1") == ok* ]] || fail "plug legs 1 beside legs 0"
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 1 set-id 2 2>&1)
[[ $? -eq 3 && $out == *"several servos answer as this id"* ]] || fail "two at id 1: $out"
[[ $(ctl "unplug legs 1") == ok* ]] || fail "unplug legs 1"
reply=$(ctl "get legs 1")
[[ $reply == *" id=1 baud=57600" ]] || fail "the refusals changed the servo: $reply"

for index in $(seq 0 11); do
  id=$((index + 2))  # id 1 stays free for the next new servo
  if ((index > 0)); then
    [[ $(ctl "plug legs $index") == ok* ]] || fail "plug legs $index"
  fi
  before=$(found 57600)
  # Only the new servo answers at 57600: the others hear only 1 Mbaud now.
  [[ $before == "57600:1 " ]] || fail "servo $index: the scan at 57600 found: $before"
  out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 1 set-id $id 2>&1) \
    || fail "servo $index: set-id: $out"
  [[ $out == *"id 1 -> $id (read back)"* ]] || fail "servo $index: set-id said: $out"
  out=$("$animrt" servo "$pty" --protocol dynamixel2 --id $id set-baud 1000000 2>&1) \
    || fail "servo $index: set-baud: $out"
  [[ $out == *"baud 57600 -> 1000000 (read back at the new rate)"* ]] \
    || fail "servo $index: set-baud said: $out"
  after=$(found 1000000)
  expected=$(for i in $(seq 2 $id); do echo "1000000:$i"; done | sort | tr '\n' ' ')
  [[ $after == "$expected" ]] || fail "servo $index: at 1000000 found: $after, expected $expected"
done

all=$("$animrt" scan "$pty" --timeout-ms 30 --protocol dynamixel2 --baud 1000000 --ids 0-14 2> /dev/null \
  | awk 'NR > 1 && $3 == 1000000 {print $4}' | sort -n | tr '\n' ' ')
[[ $all == "2 3 4 5 6 7 8 9 10 11 12 13 " ]] || fail "final scan at 1 Mbaud: $all"
# What the servos themselves now hold, seen through the sim's control interface.
for index in 0 5 11; do
  reply=$(ctl "get legs $((index + 1))")
  [[ $reply == *" id=$((index + 2)) baud=1000000" ]] || fail "servo $index: the sim holds: $reply"
done
echo ok
