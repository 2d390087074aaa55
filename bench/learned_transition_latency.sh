#!/usr/bin/env bash
# Compute time of learned cue transitions on a figure-sized model: trains a
# joint-space model of the sequence network's default shape (dense 64,
# latent 128, LSTM 3 x 128, window 32) for a few iterations on six swaying
# joints of the animatronic, serves the animatronic in real time with two
# poses entered by learned transitions over 1 s (25 frames of 0.04 s), sends
# COUNT pairs of triggers over OSC 1.2 s apart, and prints the summary's
# count and the slowest computation. The model is barely trained: its
# quality does not change the work, which is one forward and one backward
# chain per in-between.
# Usage: bench/learned_transition_latency.sh BUILD/bin/animrt [COUNT]
set -uo pipefail
animrt=$1
count=${2:-10}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
awk 'BEGIN { print "time_s,neck_pan,neck_tilt,jaw,eye_pan,eye_tilt,torso_lean";
  for (f = 0; f < 400; f++) { t = f / 25; printf "%g,%g,%g,%g,%g,%g,%g\n", t, 0.6 * sin(1.3 * t),
    0.2 * sin(0.7 * t + 1), 0.2 + 0.2 * sin(5 * t), 0.3 * sin(2.1 * t), 0.1 * cos(1.7 * t),
    0.1 * sin(0.4 * t) } }' > "$tmp/fig.csv"
"$animrt" seq train "$tmp/fig.csv" --out "$tmp/fig.model" --iterations 3 --threads 1 > /dev/null ||
  { echo "training failed"; exit 1; }
cat > "$tmp/cues.yaml" <<'YAML'
idle: rest
transition: {interpolation: learned, model: fig.model, frame_s: 0.04}
cues:
  rest:
    play: {pose: {neck_pan: 0, neck_tilt: 0, jaw: 5, eye_pan: 0, eye_tilt: 0, torso_lean: 0}}
  look:
    play: {pose: {neck_pan: 30, neck_tilt: 10, jaw: 15, eye_pan: 10, eye_tilt: 5, torso_lean: 3}}
YAML
"$animrt" serve "$root/configs/robots/animatronic.yaml" --cues "$tmp/cues.yaml" --osc-port 0 \
  --no-artnet --duration $((5 + 3 * count)) > "$tmp/out.txt" 2> "$tmp/err.txt" &
pid=$!
for _ in $(seq 100); do
  grep -q "^osc: listening" "$tmp/out.txt" && break
  sleep 0.1
done
port=$(sed -n 's/^osc: listening on 127\.0\.0\.1:\([0-9]*\)$/\1/p' "$tmp/out.txt")
sleep 4  # the start ramp
script=""
for _ in $(seq "$count"); do script+=$'send /cue/look\nsleep 1.2\nsend /cue/rest\nsleep 1.2\n'; done
/usr/bin/python3 "$root/tests/cli/osc_send.py" "$port" "$script" > /dev/null
wait $pid
grep -E "^(cues started|learned transitions)" "$tmp/out.txt"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
