#!/usr/bin/env bash
# animrt calibrate's direction jog on the quadruped's simulated servos: a
# joint whose file says direction 1 while its servo is mounted mirrored is
# jogged under a weak torque; the user (here a script that watches the
# simulated joint) says it went the wrong way, and direction -1 is written.
# Non-interactively --jog moves the joint by the jog and keeps a direction
# its servo confirms, and the joint is limp again afterwards (a hand moves it).
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
start_sim "$robot"
# The file the user calibrates: rf_hip's direction is wrong (the servo is mirrored).
wired=$tmp/robots/wired.yaml
sed '/^  rf_hip:/,/actuator:/s/direction: -1/direction: 1/' "$robot" > "$wired"
grep -A3 "^  rf_hip:" "$wired" | grep -q "id: 4, .*direction: 1}" || fail "test file not made"

# The user: answers the questions from what the simulated joint did (the
# simulator's rf_hip is mirrored: its joint angle falls as the ticks rise),
# then moves it through its range (ticks 1500, 2600, home 2000; DEV and
# MOVES for another joint) and presses Enter.
cat > "$tmp/user.py" <<'PY'
import os, socket, subprocess, sys, time
ctl, cmd = sys.argv[1], sys.argv[2:]
def ask(line):
    s = socket.socket(socket.AF_UNIX); s.connect(ctl)
    s.sendall((line + "\n").encode())
    return s.makefile().readline().strip()
dev = os.environ.get("DEV", "4")
moves = [int(t) for t in os.environ.get("MOVES", "1500 2600 2000").split()]
def ticks():
    return int(ask(f"get legs {dev}").split("ticks=")[1].split()[0])
proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                        stderr=subprocess.STDOUT)
out, start, seen = b"", None, 0
def say(text):
    proc.stdin.write(text.encode()); proc.stdin.flush()
def heard(prompt):  # the prompt, once, after what was answered so far
    global seen
    at = out.decode().find(prompt, seen)
    if at < 0: return False
    seen = at + len(prompt)
    return True
while True:
    chunk = os.read(proc.stdout.fileno(), 4096)
    if not chunk: break
    out += chunk
    if heard("by a small jog under a weak torque? [y/n] "):
        start = ticks()
        say("y\n")
    if heard("did it move in its positive direction? [y/n] "):
        moved = ticks() - start
        print(f"jog moved the servo {moved} ticks", flush=True)
        say("y\n" if -moved > 0 else "n\n")  # the mirrored joint's angle
    if heard("through its whole range"):
        interactive = "--non-interactive" not in cmd
        if start is None and interactive:  # the range came first: no jog was offered
            proc.kill(); print(out.decode()); sys.exit(1)
        for t in moves:
            time.sleep(0.15)
            assert ask(f"hand legs {dev} {t}") == "ok", "the hand could not move it"
        if interactive:
            time.sleep(0.2)
            say("\n")
proc.wait()
print(out.decode())
sys.exit(proc.returncode)
PY
out=$(timeout 60 /usr/bin/python3 "$tmp/user.py" "$tmp/ctl" "$animrt" calibrate "$wired" \
  --port "legs=$pty" --joint rf_hip 2>&1) || fail "interactive jog: $out"
moved=$(sed -n 's/^jog moved the servo \(-\?[0-9]*\) ticks$/\1/p' <<< "$out")
[[ -n $moved ]] && (( moved > 30 && moved < 90 )) || fail "the jog did not move 5 deg (57 ticks): $out"
line=$(grep -A3 "^  rf_hip:" "$wired")
[[ $line == *"zero_ticks: 2000, direction: -1}"* ]] || fail "direction not corrected: $line
$out"

# Non-interactively: lf_hip (direction 1, right) is jogged and keeps it;
# afterwards a hand moves it (the jog's torque is off again).
out=$(DEV=1 MOVES="1700 2600 2150" timeout 60 /usr/bin/python3 "$tmp/user.py" "$tmp/ctl" "$animrt" \
  calibrate "$wired" --port "legs=$pty" --joint lf_hip --non-interactive --jog \
  --seconds-per-joint 1.2 2>&1) || fail "non-interactive jog: $out"
[[ $out == *"lf_hip: it turned +"[45]"."*" deg as the file counts them"* ]] || fail "no jog: $out"
line=$(grep -A3 "^  lf_hip:" "$wired")
[[ $line == *"zero_ticks: 2150, direction: 1}"* ]] || fail "lf_hip: $line
$out"
echo "calibrate jog: ok"
