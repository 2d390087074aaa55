#!/usr/bin/env bash
# animrt record on the quadruped's simulated servos, two joints puppeteered
# through the control interface: the show holds far fewer keys than samples,
# its keys follow what was moved within 1 deg, and played back through
# `animrt run` the joints move as the hand moved them, within 1 deg. A port
# that is not a serial device, an unknown bus, an unwritable show, a
# missing microphone and one that is not paced by a clock are one line
# each, and nothing is written.
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

# The puppeteer: from the moment record says it records, turns lf_hip
# (id 1) and rf_knee (id 5, mirrored) along smooth curves at 100 Hz and logs
# the joint angles it gave them (deg, seconds since that moment).
cat > "$tmp/puppet.py" <<'PY'
import json, math, socket, subprocess, sys, time
ctl, log_path, out_path = sys.argv[1], sys.argv[2], sys.argv[3]
s = socket.socket(socket.AF_UNIX); s.connect(ctl); replies = s.makefile()
def ticks_of(dev):
    s.sendall(f"get legs {dev}\n".encode())
    return int(replies.readline().split()[1].split("=")[1])
# From where the joints rest, as a hand takes them (a jump no figure makes).
hip0 = (ticks_of(1) - 2048) * 360 / 4096
knee0 = -(ticks_of(5) - 2048) * 360 / 4096
def angles(t):
    t = min(t, 2.5)  # then held
    return (hip0 + 15 * math.sin(2 * math.pi * t / 3.0),
            knee0 + 20 * math.sin(2 * math.pi * t / 3.5))
proc = subprocess.Popen(sys.argv[4:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
out = [proc.stdout.readline()]
assert out[0].startswith("torque is off"), out[0]
t0 = time.monotonic(); log = []
while proc.poll() is None:
    t = time.monotonic() - t0
    hip, knee = angles(t)
    hip_ticks = 2048 + round(hip * 4096 / 360)
    knee_ticks = 2048 - round(knee * 4096 / 360)  # direction -1
    for dev, ticks in ((1, hip_ticks), (5, knee_ticks)):
        s.sendall(f"hand legs {dev} {ticks}\n".encode())
        assert replies.readline().startswith("ok")
    # The servos took the moves somewhere between t and now.
    log.append([t, time.monotonic() - t0, (hip_ticks - 2048) * 360 / 4096,
                -(knee_ticks - 2048) * 360 / 4096])
    time.sleep(0.01)
out += proc.stdout.readlines()
json.dump(log, open(log_path, "w"))
open(out_path, "w").write("".join(out))
sys.exit(proc.returncode)
PY
show=$tmp/robots/puppet.yaml
/usr/bin/python3 "$tmp/puppet.py" "$tmp/ctl" "$tmp/moved.json" "$tmp/out.txt" \
  "$animrt" record "$robot" --out "$show" --duration 3 --port "legs=$pty" ||
  fail "record failed: $(cat "$tmp/out.txt")"
grep -q "12 joints, [0-9]* samples over 3.0[0-9] s" "$tmp/out.txt" || fail "record: $(cat "$tmp/out.txt")"
# A sound track from a device that no clock paces (ALSA's null) is refused,
# and neither the track nor the show is left behind.
out=$("$animrt" record "$robot" --out "$tmp/take.yaml" --audio --audio-device null --duration 0.5 \
  --port "legs=$pty" 2>&1)
code=$?
[[ $code -eq 3 && $out == *"faster than real time"* ]] || fail "null sound track (exit $code): $out"
[[ ! -e $tmp/take.yaml && ! -e $tmp/take.wav ]] || fail "files left after a failed sound track"
stop_sim

# Played back: the robot with the recorded show as its motion.
sed -e 's|^  type: gait|  type: show|' -e 's|^  file: ../gaits/walk.yaml.*|  file: puppet.yaml|' \
  "$robot" > "$tmp/robots/play.yaml"
"$animrt" run "$tmp/robots/play.yaml" --lockstep --no-audio --duration 3 \
  --telemetry "$tmp/play.csv" > "$tmp/run.txt" 2>&1 || fail "playback failed: $(cat "$tmp/run.txt")"

/usr/bin/python3 - "$show" "$tmp/moved.json" "$tmp/play.csv" <<'PY' || fail "recorded show"
import bisect, csv, itertools, json, math, sys, yaml
show = yaml.safe_load(open(sys.argv[1]))
moved = json.load(open(sys.argv[2]))
def at(keys, t):  # the show's linear interpolation
    if t <= keys[0][0]: return keys[0][1]
    for (t0, v0), (t1, v1) in zip(keys, keys[1:]):
        if t <= t1: return v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    return keys[-1][1]
tracks = {name: show["joints"][name]["keys"] for name in ("lf_hip", "rf_knee")}
samples = 600
for name, keys in tracks.items():
    assert show["joints"][name]["interpolation"] == "linear"
    assert 5 < len(keys) < samples / 5, f"{name}: {len(keys)} keys"
still = [n for n in show["joints"] if n not in tracks]
assert all(len(show["joints"][n]["keys"]) == 2 for n in still), "a still joint got keys"
# When the puppeteer's clock started against the recording's or the
# playback's is not known to the millisecond: the best shift is taken, and
# the shape must then match within 1 deg everywhere.
# A move took effect between its sending and its acknowledgement: the
# closest moment of that window counts.
checked = [([sent + (acked - sent) * k / 4 for k in range(5)], hip, knee)
           for sent, acked, hip, knee in itertools.takewhile(lambda m: m[0] <= 2.6, moved)]
def worst(curve, shift, enough=math.inf):  # stops once at `enough`: it can only grow
    err = 0
    for window, hip, knee in checked:
        err = max(err, min(max(abs(curve("lf_hip", t + shift) - hip),
                               abs(curve("rf_knee", t + shift) - knee)) for t in window))
        if err >= enough: break
    return err
def best(curve, shifts):  # the least worst() over the shifts
    least = math.inf
    for s in shifts:
        least = min(least, worst(curve, s, least))
    return least
shifts = [i * 0.002 for i in range(-50, 51)]
keys_err = best(lambda n, t: at(tracks[n], t), shifts)
assert keys_err <= 1.0, f"show keys stray {keys_err:.2f} deg from what was moved"
rows = list(csv.DictReader(open(sys.argv[3])))
times = [float(r["time_s"]) for r in rows]
meas = {n: [math.degrees(float(r[n + "_meas_rad"])) for r in rows] for n in tracks}
def played(n, t):  # the first sample at or after t (the last one after the run)
    return meas[n][min(bisect.bisect_left(times, t), len(times) - 1)]
# The playback starts after the start ramp: search the shift over the run.
play_err = best(played, [i * 0.005 for i in range(0, int((times[-1] - 3) / 0.005))])
assert play_err <= 1.0, f"playback strays {play_err:.2f} deg from what was moved"
print(f"keys within {keys_err:.2f} deg, playback within {play_err:.2f} deg")
PY
# Bad input: one line each, no show written.
bad() {  # bad EXIT TEXT ARGS...
  local want=$1 text=$2
  shift 2
  out=$("$animrt" record "$robot" "$@" 2>&1)
  code=$?
  [[ $code -eq $want && $out == *"$text"* && $(wc -l <<< "$out") -eq 1 ]] ||
    fail "record $* (exit $code): $out"
}
bad 3 "not a character device (not a serial port)" --out "$tmp/bad.yaml" --port "legs=$robot"
bad 1 "has no bus named" --out "$tmp/bad.yaml" --port "arms=/dev/null"
bad 1 "--out: cannot write" --out "$tmp/no/such/folder/show.yaml"
bad 3 'ALSA capture device "animrt_no_such_device"' --out "$tmp/bad.yaml" --audio \
  --audio-device animrt_no_such_device
[[ ! -e $tmp/bad.yaml ]] || fail "a show was written after an error"
echo "record: ok"
