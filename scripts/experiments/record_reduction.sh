#!/usr/bin/env bash
# Key reduction of a recorded show: the quadruped's 12 simulated servos
# turned by a scripted hand (each joint a sum of two slow sines, as a
# puppeteer's smooth motion), recorded by `animrt record` for 10 s at the
# loop rate (200 Hz) and reduced at 0.5 deg (or $3). Prints record's line
# and the keys per joint.
# Usage: scripts/experiments/record_reduction.sh build/bin/animrt . [TOLERANCE_DEG]
set -uo pipefail
animrt=$(realpath "$1")
root=$(realpath "$2")
tolerance=${3:-0.5}
tmp=$(mktemp -d)
sim_pid=""
fail() { echo "FAIL: $*"; exit 1; }
trap 'stop_sim; rm -rf "$tmp"' EXIT
source "$root/tests/cli/commission_sim.bash"
copy_robot quadruped
robot=$tmp/robots/quadruped.yaml
start_sim "$robot"
/usr/bin/python3 - "$tmp/ctl" "$animrt" "$robot" "$tmp/show.yaml" "$pty" "$tolerance" <<'PY'
import math, socket, subprocess, sys, time
ctl, animrt, robot, show, pty, tol = sys.argv[1:]
s = socket.socket(socket.AF_UNIX); s.connect(ctl); replies = s.makefile()
def ask(line):
    s.sendall((line + "\n").encode()); return replies.readline()
start = [int(ask(f"get legs {i}").split()[1].split("=")[1]) for i in range(1, 13)]
proc = subprocess.Popen([animrt, "record", robot, "--out", show, "--duration", "10",
                         "--tolerance-deg", tol, "--port", f"legs={pty}"],
                        stdout=subprocess.PIPE, text=True)
proc.stdout.readline()
t0 = time.monotonic()
updates = 0
while proc.poll() is None:
    t = time.monotonic() - t0
    lines = ""
    for i in range(12):
        deg = 20 * math.sin(2 * math.pi * t / (1.6 + 0.2 * i)) + 6 * math.sin(2 * math.pi * t / (0.7 + 0.05 * i))
        lines += f"hand legs {i + 1} {start[i] + round(deg * 4096 / 360)}\n"
    s.sendall(lines.encode())  # all twelve at once: the hand moves them together
    for i in range(12): replies.readline()
    updates += 1
    time.sleep(0.005)
print(proc.stdout.read(), end="")
print(f"hand: {updates / (time.monotonic() - t0):.0f} updates/s of all twelve joints")
PY
/usr/bin/python3 - "$tmp/show.yaml" <<'PY'
import sys, yaml
show = yaml.safe_load(open(sys.argv[1]))
print("keys per joint:", " ".join(f"{n}={len(j['keys'])}" for n, j in show["joints"].items()))
PY
