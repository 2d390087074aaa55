#!/usr/bin/env bash
# animrt scan and animrt servo against `animrt sim` serving the quadruped's
# 12 Dynamixel servos on a pty: the scan lists them (model, position,
# torque off), a servo given a new id is found there and no longer at the
# old one, the drafted robot file validates, and bad input (not a serial
# port, a busy port, a line that answers garbage, a taken id) gets one
# clear line each.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
junk_pid=""
trap '[[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null; [[ -n $junk_pid ]] && kill $junk_pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$animrt" sim "$root/configs/robots/quadruped.yaml" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^serial " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $kind == serial && $pty == /dev/pts/* ]] || fail "sim line: $(cat "$tmp/sim.txt")"

scan() { "$animrt" scan "$pty" --timeout-ms 30 --protocol dynamixel2 --baud 1000000 --ids 0-25 "$@"; }

# The 12 servos, one row each, as the simulated XM430-W210 reports itself.
scan > "$tmp/scan.txt" 2> "$tmp/progress.txt" || fail "scan: $(cat "$tmp/scan.txt" "$tmp/progress.txt")"
ids=$(awk 'NR > 1 && $2 == "dynamixel2" && $3 == 1000000 {print $4}' "$tmp/scan.txt" | tr '\n' ' ')
[[ $ids == "1 2 3 4 5 6 7 8 9 10 11 12 " ]] || fail "ids found: $ids; $(cat "$tmp/scan.txt")"
grep -q "XM430-W210 (1030)  38 .* off" "$tmp/scan.txt" || fail "model/torque: $(cat "$tmp/scan.txt")"
grep -q "dynamixel2 at 1000000" "$tmp/progress.txt" || fail "no progress line: $(cat "$tmp/progress.txt")"

# A draft robot file from the scan, valid as written.
scan --write-robot "$tmp/draft.yaml" > "$tmp/draft.txt" 2>&1 || fail "draft: $(cat "$tmp/draft.txt")"
"$animrt" validate "$tmp/draft.yaml" > "$tmp/validate.txt" 2>&1 \
  || fail "draft does not validate: $(cat "$tmp/validate.txt")"
grep -q "ok (12 joints, 1 bus, 12 devices" "$tmp/validate.txt" || fail "draft: $(cat "$tmp/validate.txt")"

# A new id, read back, and found there by the next scan.
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 5 --baud 1000000 set-id 21 2>&1) \
  || fail "set-id: $out"
[[ $out == *"id 5 -> 21 (read back)"* ]] || fail "set-id said: $out"
scan > "$tmp/scan2.txt" 2>&1 || fail "second scan: $(cat "$tmp/scan2.txt")"
ids=$(awk 'NR > 1 && $2 == "dynamixel2" {print $4}' "$tmp/scan2.txt" | sort -n | tr '\n' ' ')
[[ $ids == "1 2 3 4 6 7 8 9 10 11 12 21 " ]] || fail "ids after set-id: $ids"

# A taken id is refused before anything is written.
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 21 --baud 1000000 set-id 4 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"id 4 is already taken"* ]] \
  || fail "taken id: $out"
# A servo that is not there.
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 99 --baud 1000000 set-id 98 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"id 99"*"no answer to a ping"* ]] \
  || fail "absent servo: $out"
# An id out of range is told before the line is asked anything (it was
# "no answer to a ping" for an absent servo).
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 99 --baud 1000000 set-id 1000 2>&1)
[[ $? -eq 1 && $out == "error: set-id: the new id 1000 is outside 0..252 (dynamixel2)" ]] \
  || fail "new id out of range: $out"
out=$("$animrt" servo "$pty" --protocol dynamixel2 --id 253 --baud 1000000 reboot 2>&1)
[[ $? -eq 1 && $out == "error: --id 253 is outside 0..252 (dynamixel2)" ]] || fail "--id 253: $out"
# A factory reset is not done unconfirmed.
out=$(echo n | "$animrt" servo "$pty" --protocol dynamixel2 --id 21 --baud 1000000 factory-reset 2>&1)
[[ $? -ne 0 && $out == *"factory reset not confirmed"* ]] || fail "unconfirmed reset: $out"

# Mode, limits, reboot and factory reset, each read back; the scan shows
# the mode until the reset puts it back to position control.
servo21() { "$animrt" servo "$pty" --protocol dynamixel2 --id 21 --baud 1000000 "$@" 2>&1; }
out=$(servo21 set-mode extended-position) && [[ $out == *"operating mode extended-position (read back)"* ]] \
  || fail "set-mode: $out"
out=$(servo21 set-limits 1000 3000) && [[ $out == *"position limits 1000..3000 ticks (read back)"* ]] \
  || fail "set-limits: $out"
out=$(servo21 reboot) && [[ $out == *"rebooted, answers again"* ]] || fail "reboot: $out"
scan --write-robot "$tmp/draft3.yaml" > "$tmp/scan3.txt" 2>&1
grep -q "  21  .*operating mode extended-position" "$tmp/scan3.txt" || fail "mode lost: $(cat "$tmp/scan3.txt")"
# The draft keeps it multi-turn (and only it), with the comment why.
grep -A7 "^  id21:" "$tmp/draft3.yaml" | grep -q "actuator: {.*, multi_turn: true}" \
  && grep -A7 "^  id21:" "$tmp/draft3.yaml" | grep -q "# multi_turn: found in extended position mode" \
  && [[ $(grep -c "multi_turn: true" "$tmp/draft3.yaml") == 1 ]] || fail "draft: $(cat "$tmp/draft3.yaml")"
grep -q "multi_turn" "$tmp/draft.yaml" && fail "multi_turn in the first draft"
"$animrt" validate "$tmp/draft3.yaml" > "$tmp/validate3.txt" 2>&1 \
  || fail "multi-turn draft does not validate: $(cat "$tmp/validate3.txt")"
out=$(servo21 factory-reset --yes) && [[ $out == *"factory reset (id and baud rate kept)"* ]] \
  || fail "factory reset: $out"
scan > "$tmp/scan4.txt" 2>&1
grep -q "  21  " "$tmp/scan4.txt" && ! grep -q "operating mode" "$tmp/scan4.txt" \
  || fail "after the reset: $(cat "$tmp/scan4.txt")"
# Limits that leave no travel (a tick apart): the servo is left out of the
# draft, saying why, and the draft still validates.
out=$(servo21 set-limits 2048 2049) || fail "set-limits 2048 2049: $out"
scan --write-robot "$tmp/draft5.yaml" > "$tmp/scan5.txt" 2>&1 || fail "draft5: $(cat "$tmp/scan5.txt")"
grep -q "# left out: id 21 .* leave no travel" "$tmp/draft5.yaml" && ! grep -q "^  id21:" "$tmp/draft5.yaml" \
  || fail "draft5: $(cat "$tmp/draft5.yaml")"
"$animrt" validate "$tmp/draft5.yaml" > "$tmp/validate5.txt" 2>&1 \
  || fail "draft5 does not validate: $(cat "$tmp/validate5.txt")"
grep -q "ok (11 joints" "$tmp/validate5.txt" || fail "draft5: $(cat "$tmp/validate5.txt")"
out=$(servo21 set-mode walking)
[[ $? -eq 3 && $out == *"unknown mode 'walking': expected one of current, velocity, position"* ]] \
  || fail "bad mode: $out"

# Not a serial port: one line each.
out=$("$animrt" scan /dev/null --baud 57600 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"/dev/null"*"not a serial port"* ]] \
  || fail "/dev/null: $out"
touch "$tmp/file"
out=$("$animrt" scan "$tmp/file" --baud 57600 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"not a character device"* ]] \
  || fail "regular file: $out"
out=$("$animrt" scan "$tmp/absent" 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"$tmp/absent"* ]] || fail "absent port: $out"

# A busy port: another program has it open.
sleep 30 < "$pty" &
holder=$!
sleep 0.2
out=$("$animrt" scan "$pty" --baud 1000000 2>&1)
code=$?
kill $holder 2>/dev/null
[[ $code -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"busy: open in process $holder"* ]] \
  || fail "busy port: $out"

# A line whose far end answers every request with junk: no device, no crash.
/usr/bin/python3 - "$tmp/junk_pty" <<'PY' &
import os, sys, select
master, slave = os.openpty()
open(sys.argv[1] + ".tmp", "w").write(os.ttyname(slave))
os.rename(sys.argv[1] + ".tmp", sys.argv[1])
while True:
    select.select([master], [], [])
    os.read(master, 4096)
    os.write(master, bytes([0xFF, 0xFF, 0xFD, 0x00, 0x07, 0x09, 0x00, 0x55, 0x13, 0x37, 0xFF, 0xFF]))
PY
junk_pid=$!
for _ in $(seq 50); do [[ -s $tmp/junk_pty ]] && break; sleep 0.1; done
junk=$(cat "$tmp/junk_pty")
out=$("$animrt" scan "$junk" --protocol dynamixel2,feetech --baud 1000000 --ids 0-3 2> /dev/null)
[[ $? -eq 0 && $out == *"no device answered"* && $out == *"garbage: dynamixel2 at 1000000: "* \
  && $out == *"garbage: feetech at 1000000: "* && $out != *collision* ]] || fail "junk line: $out"

# A factory-new Feetech STS servo (id 1 at 1 Mbaud): given id 3 and
# 500000 baud, a scan of every Feetech rate finds it there alone; a reboot,
# which the family has no instruction for, is refused in one line; two new
# servos plugged in at once are a collision at id 1.
kill $sim_pid
wait $sim_pid 2> /dev/null
: > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
"$animrt" sim "$root/configs/robots/arm_sts.yaml" --factory --control "$tmp/ctl" > "$tmp/sim.txt" 2>&1 &
sim_pid=$!
for _ in $(seq 50); do
  grep -q "^control " "$tmp/sim.txt" && break
  sleep 0.1
done
read -r kind bus pty < <(grep "^serial " "$tmp/sim.txt")
[[ $pty == /dev/pts/* ]] || fail "feetech sim line: $(cat "$tmp/sim.txt")"
feetech() { "$animrt" scan "$pty" --timeout-ms 30 --protocol feetech --ids 0-4 2> /dev/null | awk 'NR > 1 {print $2 ":" $3 ":" $4}' | tr '\n' ' '; }
[[ $(feetech) == "feetech_sts:1000000:1 " ]] || fail "new feetech servo: $(feetech)"
out=$("$animrt" servo "$pty" --protocol feetech --id 1 set-id 3 2>&1) || fail "feetech set-id: $out"
out=$("$animrt" servo "$pty" --protocol feetech --id 3 set-baud 500000 2>&1) \
  || fail "feetech set-baud: $out"
[[ $(feetech) == "feetech_sts:500000:3 " ]] || fail "feetech after set-id/baud: $(feetech)"
out=$("$animrt" servo "$pty" --protocol feetech --id 3 --baud 500000 reboot 2>&1)
[[ $? -eq 3 && $(wc -l <<< "$out") -eq 1 && $out == *"no reboot instruction"* ]] \
  || fail "feetech reboot: $out"
# Two more new servos plugged in at once: both answer as id 1.
for index in 1 2; do
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "plug arm $index" > "$tmp/plug.txt"
  [[ $(cat "$tmp/plug.txt") == ok* ]] || fail "plug arm $index: $(cat "$tmp/plug.txt")"
done
out=$("$animrt" scan "$pty" --timeout-ms 30 --protocol feetech --baud 1000000 --ids 0-4 2> /dev/null)
[[ $out == *"collision: feetech id 1 at 1000000 baud: "* && $out != *"collision: feetech id "[0234]* ]] \
  || fail "feetech collision: $out"
echo ok
