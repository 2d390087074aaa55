#!/usr/bin/env bash
# animrt record --sound: the sound track recorded beside the puppeteered
# motion from a capture spec as a head's `capture` key takes it, here
# pipe:PATH (a FIFO fed at real time stands in for a microphone on a machine
# without a sound card). The WAV beside the show holds exactly the samples
# fed (a whole-range pattern, 16-bit mono at 48 kHz), from the first on,
# and the show names it as its sound track.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
sim_pid=""
feed_pid=""
fail() { echo "FAIL: $*"; exit 1; }
trap '[[ -n $feed_pid ]] && kill $feed_pid 2>/dev/null; stop_sim; rm -rf "$tmp"' EXIT
source "$root/tests/cli/commission_sim.bash"

copy_robot quadruped
robot=$tmp/robots/quadruped.yaml
start_sim "$robot"

# The microphone: 3 s of s16le at 48 kHz in 10 ms blocks, paced by the wall
# clock from the moment the recorder opens the FIFO; what it fed is kept.
mkfifo "$tmp/mic"
/usr/bin/python3 - "$tmp/mic" "$tmp/fed.raw" <<'PY' &
import struct, sys, time
pipe = open(sys.argv[1], "wb", buffering=0)
fed = open(sys.argv[2], "wb")
rate, block = 48000, 480
t0 = time.monotonic()
try:
    for b in range(300):
        data = struct.pack("<%dh" % block,
                           *(((i * 7919) % 65536) - 32768 for i in range(b * block, (b + 1) * block)))
        pipe.write(data)
        fed.write(data)
        fed.flush()
        time.sleep(max(0.0, t0 + (b + 1) * block / rate - time.monotonic()))
except BrokenPipeError:
    pass  # the recorder has finished
PY
feed_pid=$!

out=$("$animrt" record "$robot" --out "$tmp/take.yaml" --sound "pipe:$tmp/mic" --duration 1.0 \
  --port "legs=$pty" 2>&1) || fail "record: $out"
grep -q '^audio: {file: "take.wav", offset_s: ' "$tmp/take.yaml" || fail "show: $(head -8 "$tmp/take.yaml")"
[[ -f $tmp/take.wav ]] || fail "no take.wav: $out"

/usr/bin/python3 - "$tmp/take.wav" "$tmp/fed.raw" <<'PY' || fail "sound track"
import sys, wave
w = wave.open(sys.argv[1])
assert (w.getnchannels(), w.getsampwidth(), w.getframerate()) == (1, 2, 48000), w.getparams()
frames = w.readframes(w.getnframes())
fed = open(sys.argv[2], "rb").read()
n = len(frames) // 2
# About the second recorded (the motion's), at least half of it, and
# sample for sample what was fed, from its first sample.
assert 24000 <= n <= len(fed) // 2, (n, len(fed) // 2)
assert frames == fed[:len(frames)], "the track is not the samples fed"
PY
echo ok
