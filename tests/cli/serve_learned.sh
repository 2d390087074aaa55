#!/usr/bin/env bash
# `animrt serve --lockstep` with a cue whose transition is learned: the
# in-between is computed and played (counted in the summary), a model made
# slow by the test hook falls back to the crossfade (counted), and a
# transition whose model is missing or moves joints the robot lacks is
# refused before anything moves.
set -uo pipefail
animrt=$1
root=$2
here=$(dirname "$0")
source "$root/tests/cli/serve.bash"

# The fuzz corpus's tiny joint model (hip, knee), its joints renamed to the
# animatronic's neck and its checksum written again.
/usr/bin/python3 - "$root/tests/fuzz/corpus/seq_model_file/tiny_joints.model" "$tmp/neck.model" <<'PY' ||
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()[:-4]
old = struct.pack("<I", 3) + b"hip" + struct.pack("<I", 4) + b"knee"
new = struct.pack("<I", 8) + b"neck_pan" + struct.pack("<I", 9) + b"neck_tilt"
assert data.count(old) == 1
data = data.replace(old, new)
open(sys.argv[2], "wb").write(data + struct.pack("<I", zlib.crc32(data)))
PY
  fail "could not write the model"

cues="idle: rest
cues:
  rest:
    play: {pose: {neck_pan: 0, neck_tilt: 0}}
  look:
    play: {pose: {neck_pan: 30, neck_tilt: 10}}
    transition: {interpolation: learned, model: neck.model, frame_s: 0.04}"
printf '%s\n' "$cues" > "$tmp/cues.yaml"

# Serves the cue file, asks for `look`, then stops; $out is what it printed.
serve_look() {
  start_serve "$root/configs/robots/animatronic.yaml" --cues "$tmp/cues.yaml" \
    --lockstep --no-realtime --osc-port 0 --no-artnet
  [[ $line =~ ^osc:\ listening\ on\ 127\.0\.0\.1:([0-9]+)$ ]] || fail "no OSC line: '$line'"
  /usr/bin/python3 "$here/osc_send.py" "${BASH_REMATCH[1]}" "send /cue/look
sleep 1.0
send /stop" > /dev/null || fail "the sender failed"
  wait_exit
  out=$(cat "$tmp/out.txt")
  [[ $code == 0 ]] || fail "exit $code: $out $(cat "$tmp/err.txt")"
  grep -q "ended by stop request" <<<"$out" || fail "not stopped by /stop: $out"
  grep -qE "^cues started: rest 1 look 1$" <<<"$out" || fail "look did not play: $out"
}

serve_look
grep -qE "^learned transitions: 1 played, 0 crossfaded \(not computed within 2000 ms\), 0 crossfaded \(unusable\)" <<<"$out" ||
  fail "the learned transition did not play: $(grep -i learned <<<"$out")"
# Never measured against interpolation: the show path's warning, with the cue file's line.
grep -q "$tmp/cues.yaml:7: cues.look.transition.model: .*never measured" "$tmp/err.txt" ||
  fail "no warning for the unmeasured model: $(cat "$tmp/err.txt")"
grep "^learned transitions" <<<"$out"

# Slower than the lockstep clock's 2 s of wall time.
ANIMRT_TEST_TRANSITION_DELAY_S=2.5 serve_look
grep -qE "^learned transitions: 0 played, 1 crossfaded \(not computed within 2000 ms\)" <<<"$out" ||
  fail "a slow model did not fall back to the crossfade: $(grep -i learned <<<"$out")"
grep "^learned transitions" <<<"$out"

# Refused at load, naming the file, the line and the key.
bad_cues "${cues/neck.model/none.model}" 7 "cues.look.transition.model: file not found"
printf 'ANSEQNN\nbroken' > "$tmp/broken.model"
bad_cues "${cues/neck.model/broken.model}" 7 "cues.look.transition.model: model"
bad_cues "${cues/neck.model/$root/tests/fuzz/corpus/seq_model_file/tiny_joints.model}" 7 \
  "cues.look.transition.model: .*moves joint \"hip\", which robot animatronic does not have"
echo ok
