#!/usr/bin/env bash
# animrt calibrate on the quadruped's simulated servos, each joint turned by
# hand through the control interface while it is followed: zero_ticks and the
# limits land within 1 deg of what was moved, in place, every other byte of
# the file as it was; interactively the user's positive sets the
# direction. A range across the servo's seam, a joint left still, a read-only file and a file edited
# meanwhile are refused with one line and the file is left alone.
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

# The hand: for each joint calibrate announces, min, max, then home (ticks).
cat > "$tmp/hand.py" <<'PY'
import json, os, re, socket, subprocess, sys, time
ctl, moves, out = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3]
cmd = sys.argv[4:]
def hand(bus_id, ticks):
    s = socket.socket(socket.AF_UNIX); s.connect(ctl)
    s.sendall(f"hand legs {bus_id} {ticks}\n".encode())
    assert s.makefile().readline().startswith("ok")
proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                        stderr=subprocess.STDOUT, text=True)
log = []
def enter():
    time.sleep(0.2)
    proc.stdin.write("\n"); proc.stdin.flush()
for line in proc.stdout:
    log.append(line)
    m = re.match(r"(\w+): (?:move it|now move it a little in its (positive))", line)
    if m and m.group(2):  # interactive: the hand turns it 100 ticks up, the user's positive
        bus_id, lo, hi, home = moves[m.group(1)]
        hand(bus_id, home + 100)
        enter()
        continue
    if m and m.group(1) in moves:
        bus_id, lo, hi, home = moves[m.group(1)]
        if os.environ.get("EDIT_MEANWHILE"):  # someone edits the file during the calibration
            open(os.environ["EDIT_MEANWHILE"], "a").write("# edited meanwhile\n")
        for ticks in (lo, hi, home):
            time.sleep(0.15)
            hand(bus_id, ticks)
        if "--non-interactive" not in cmd:
            enter()
proc.wait()
open(out, "w").write("".join(log))
sys.exit(proc.returncode)
PY
calibrate() {  # calibrate MOVES_JSON OUT ARGS...: with the hand moving the joints
  local moves=$1 out=$2
  shift 2
  /usr/bin/python3 "$tmp/hand.py" "$tmp/ctl" "$moves" "$out" \
    "$animrt" calibrate "$robot" --port "legs=$pty" "$@"
}

cp "$robot" "$tmp/original.yaml"
# id, min, max, home in ticks. rf_knee is mounted mirrored (direction -1).
moves='{"lf_hip": [1, 1700, 2600, 2150], "rf_knee": [5, 1500, 2800, 1990], "lh_ankle": [9, 1400, 2700, 2348]}'
calibrate "$moves" "$tmp/out.txt" --non-interactive --seconds-per-joint 0.9 --joint lf_hip --joint rf_knee \
  --joint lh_ankle || fail "calibrate failed: $(cat "$tmp/out.txt")"
grep -q "3 joints calibrated" "$tmp/out.txt" || fail "no summary: $(cat "$tmp/out.txt")"
"$animrt" validate "$robot" > /dev/null || fail "the calibrated file does not load"

/usr/bin/python3 - "$tmp/original.yaml" "$robot" "$moves" <<'PY' || fail "calibrated values or layout"
import json, re, sys
old = open(sys.argv[1]).read().split("\n")
new = open(sys.argv[2]).read().split("\n")
moves = json.loads(sys.argv[3])
assert len(old) == len(new), "line count changed"
# Which joint block each line is in.
joint, owner = None, []
for line in old:
    m = re.match(r"  (\w+):$", line)
    if m: joint = m.group(1)
    if re.match(r"\S", line): joint = None
    owner.append(joint)
mask = lambda s: re.sub(r"\b(min_deg|max_deg|zero_ticks|direction): -?[0-9.]+", r"\1: X", s)
for i, (a, b) in enumerate(zip(old, new)):
    if a != b:
        assert owner[i] in moves, f"line {i+1} changed outside a calibrated joint:\n{a}\n{b}"
        assert mask(a) == mask(b), f"line {i+1} changed beyond its values:\n{a}\n{b}"
def joint_values(lines, name):
    start = next(i for i, l in enumerate(lines) if l == f"  {name}:")
    block = "\n".join(lines[start:start + 4])
    num = lambda key: float(re.search(key + r": (-?[0-9.]+)", block).group(1))
    return num("min_deg"), num("max_deg"), num("zero_ticks"), num("direction"), num("home_deg")
for name, (dev, lo, hi, home) in moves.items():
    mn, mx, zero, direction, home_deg = joint_values(new, name)
    d = joint_values(old, name)[3]
    assert direction == d, f"{name}: direction changed"
    assert abs(zero - home) <= 1, f"{name}: zero_ticks {zero}, home was {home}"
    assert home_deg == 0
    ends = sorted(d * (t - home) * 360 / 4096 for t in (lo, hi))
    assert abs(mn - ends[0]) <= 1 and abs(mx - ends[1]) <= 1, f"{name}: {mn}..{mx}, moved {ends}"
PY

# Interactively, with Enter from the user: rf_hip is mounted mirrored
# (direction -1) but its user's positive is up the ticks, so it becomes 1.
calibrate '{"rf_hip": [4, 1500, 2600, 2000]}' "$tmp/inter.txt" --joint rf_hip --no-jog ||
  fail "interactive calibrate: $(cat "$tmp/inter.txt")"
line=$(grep -A3 "^  rf_hip:" "$robot")
[[ $line == *"min_deg: -43.9, max_deg: 52.7,"* && $line == *"zero_ticks: 2000, direction: 1}"* ]] ||
  fail "interactive rf_hip: $line"

# A range across the servo's 4095 -> 0 seam (the servo reports 4146 as 50):
# refused with the range unwrapped, the file untouched.
cp "$robot" "$tmp/before.yaml"
calibrate '{"lh_hip": [7, 3900, 50, 3950]}' "$tmp/seam.txt" --non-interactive --joint lh_hip \
  --seconds-per-joint 0.9
code=$?
[[ $code -ne 0 ]] && grep -q "lh_hip: its range, [0-9]* .. 4146 ticks, crosses its servo's 4095 -> 0 seam" \
  "$tmp/seam.txt" || fail "seam (exit $code): $(cat "$tmp/seam.txt")"
cmp -s "$robot" "$tmp/before.yaml" || fail "file changed after a range across the seam"
ctl "hand legs 7 2048" > /dev/null  # back inside its limits

# A joint left where it is: refused, the file untouched.
out=$("$animrt" calibrate "$robot" --non-interactive --port "legs=$pty" --joint lf_knee \
  --seconds-per-joint 0.3 2>&1)
code=$?
[[ $code -ne 0 && $out == *"lf_knee: moved through only"* ]] || fail "still joint (exit $code): $out"
cmp -s "$robot" "$tmp/before.yaml" || fail "file changed after a refused calibration"

# A joint the robot does not have: one line, before anything is followed.
out=$("$animrt" calibrate "$robot" --non-interactive --port "legs=$pty" --joint tail 2>&1)
code=$?
[[ $code -eq 1 && $out == *'--joint "tail": the robot file'*"has no such joint" &&
   $(wc -l <<< "$out") -eq 1 ]] || fail "unknown joint (exit $code): $out"
cmp -s "$robot" "$tmp/before.yaml" || fail "file changed after an unknown joint"

# One bus given two ports: refused, naming both (the last one was taken).
out=$("$animrt" calibrate "$robot" --non-interactive --port "legs=$pty" --port "legs=/dev/ttyUSB7" \
  --joint lf_knee 2>&1)
code=$?
[[ $code -eq 1 && $out == *"--port \"legs=/dev/ttyUSB7\": bus \"legs\" is given a port twice (also \"legs=$pty\")"* ]] \
  || fail "a bus given two ports (exit $code): $out"

# A read-only file: one line, exit 2, untouched.
chmod 444 "$robot"
calibrate '{"lf_knee": [2, 1800, 2400, 2000]}' "$tmp/ro.txt" --non-interactive --joint lf_knee --seconds-per-joint 0.7
code=$?
[[ $code -eq 2 ]] && grep -q "quadruped.yaml: is read-only" "$tmp/ro.txt" ||
  fail "read-only (exit $code): $(cat "$tmp/ro.txt")"
chmod 644 "$robot"
cmp -s "$robot" "$tmp/before.yaml" || fail "read-only file changed"

# Edited on disk while the joint was followed: refused, the edit kept.
EDIT_MEANWHILE=$robot calibrate '{"lf_knee": [2, 1800, 2400, 2000]}' "$tmp/edit.txt" \
  --non-interactive --joint lf_knee --seconds-per-joint 0.9
code=$?
[[ $code -eq 2 ]] && grep -q "changed on disk" "$tmp/edit.txt" ||
  fail "edited meanwhile (exit $code): $(cat "$tmp/edit.txt")"
[[ $(tail -1 "$robot") == "# edited meanwhile" ]] || fail "the edit on disk was overwritten"
[[ ! -e $robot.tmp ]] || fail "temporary file left behind"
echo "calibrate: ok"
