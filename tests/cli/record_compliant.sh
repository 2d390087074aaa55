#!/usr/bin/env bash
# animrt record --compliant on the quadruped's simulated servos: the
# recorded joint is held by a weak torque (current-based position mode at
# 10 % of its current limit) that a hand overpowers, it stays where the hand
# leaves it (the recorder's goal follows the hand), the show holds what was
# moved within 1 deg, and afterwards torque is off and the servo is back in
# position mode. A torque a hand cannot overpower (40 %) refuses the hand.
# A Feetech STS servo is held the same way by its Torque Limit. A simulator
# stopped by SIGINT while it starts ends.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
fail() { echo "FAIL: $*"; exit 1; }
trap 'stop_sim; rm -rf "$tmp"' EXIT
source "$root/tests/cli/commission_sim.bash"

copy_robot quadruped
robot=$tmp/robots/quadruped.yaml
# A simulator stopped while it starts ends all the same, whenever the SIGINT
# comes: before its handler is in place (its default action) or after.
for delay in 0 0.01 0.03 0.06; do
  launch_sim "$robot"
  sleep "$delay"
  stop_sim
done
start_sim "$robot"

# The hand: once record holds the figure, lf_hip (id 1) to +26.4 deg, then
# to -17.6 deg; what the servo says half a second after each move.
cat > "$tmp/hand.py" <<'PY'
import socket, subprocess, sys, time
ctl = sys.argv[1]
def ask(line):
    s = socket.socket(socket.AF_UNIX); s.connect(ctl)
    s.sendall((line + "\n").encode())
    return s.makefile().readline().strip()
proc = subprocess.Popen(sys.argv[2:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
first = proc.stdout.readline()
print(first, end="")
if first.startswith("held by a weak torque"):
    time.sleep(0.3)
    for ticks in (2348, 1848):
        print("hand", ticks, ask(f"hand legs 1 {ticks}"))
        time.sleep(0.5)
        print("then", ask("get legs 1"))
print("".join(proc.stdout.readlines()), end="")
sys.exit(proc.wait())
PY
show=$tmp/robots/held.yaml
out=$(/usr/bin/python3 "$tmp/hand.py" "$tmp/ctl" "$animrt" record "$robot" --out "$show" \
  --joint lf_hip --compliant 10 --duration 2 --port "legs=$pty" 2>&1) || fail "record: $out"
[[ $out == "held by a weak torque: move the figure"* ]] || fail "not held: $out"
grep -q "^hand 2348 ok" <<< "$out" && grep -q "^hand 1848 ok" <<< "$out" || fail "hand refused: $out"
for ticks in 2348 1848; do
  grep -Eq "^then ok ticks=$ticks torque=1 " <<< "$out" ||
    fail "not held at $ticks with torque on: $out"
done
/usr/bin/python3 - "$show" <<'PY' || fail "recorded show: $(cat "$show")"
import sys, yaml
keys = yaml.safe_load(open(sys.argv[1]))["joints"]["lf_hip"]["keys"]
values = [v for _, v in keys]
for want in (300 * 360 / 4096, -200 * 360 / 4096):
    assert any(abs(v - want) <= 1.0 for v in values), f"{want:.1f} deg not recorded: {values}"
assert abs(values[-1] - (-200 * 360 / 4096)) <= 1.0, f"ends at {values[-1]}"
PY
[[ $(ctl "get legs 1") == "ok ticks="*" torque=0 "* ]] || fail "torque left on: $(ctl "get legs 1")"
# Back in position mode (3): a scan notes any other operating mode.
scan=$("$animrt" scan "$pty" --protocol dynamixel2 --baud 1000000 --ids 1-1 2>&1)
[[ $scan == *"XM430"* && $scan != *"operating mode"* ]] || fail "operating mode left changed: $scan"

# A torque stronger than a hand: the hand is refused while record holds it.
out=$(/usr/bin/python3 "$tmp/hand.py" "$tmp/ctl" "$animrt" record "$robot" --out "$tmp/strong.yaml" \
  --joint lf_hip --compliant 40 --duration 1 --port "legs=$pty" 2>&1) || fail "record 40 %: $out"
grep -q "^hand 2348 error: torque is on" <<< "$out" || fail "a hand overpowered 40 %: $out"
stop_sim

# A Feetech STS arm: held by a Torque Limit of 10 % of its maximum torque.
copy_robot arm_sts
ln -sfn "$root/configs/shows" "$tmp/shows"
rm -f "$tmp/ctl"
start_sim "$tmp/robots/arm_sts.yaml"
sed -i 's/legs/arm/g' "$tmp/hand.py"
out=$(/usr/bin/python3 "$tmp/hand.py" "$tmp/ctl" "$animrt" record "$tmp/robots/arm_sts.yaml" \
  --out "$tmp/arm.yaml" --joint shoulder_pan --compliant 10 --duration 2 --port "arm=$pty" 2>&1) ||
  fail "record the arm: $out"
for ticks in 2348 1848; do
  grep -q "^hand $ticks ok" <<< "$out" && grep -Eq "^then ok ticks=$ticks torque=1 " <<< "$out" ||
    fail "arm not held at $ticks: $out"
done
[[ $(ctl "get arm 1") == "ok ticks="*" torque=0 "* ]] || fail "arm: torque left on: $(ctl "get arm 1")"
echo "record compliant: ok"
