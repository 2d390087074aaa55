#!/usr/bin/env bash
# `animrt serve` chases SMPTE LTC timecode read from a WAV file in real time:
# the WAV is written by the test from the standard's bit layout, with a jump
# (00:00:00:24 -> 00:10:00:00) and a dropout (10 frames of silence). Cues
# bound to timecode starts are asked for as the timecode crosses them; after
# the jump the cue that should be playing at the new time re-syncs; a cue
# due during the dropout comes on the freewheeling clock; the end of the
# signal is a dropout, then lost. A bad timecode in the cue file stops
# everything before it starts.
set -uo pipefail
animrt=$1
root=$2
source "$root/tests/cli/serve.bash"
robot="$root/configs/robots/animatronic.yaml"

bad_cues $'idle: rest\nltc: {fps: 25}\ncues:\n  rest: {play: {pose: {eye_pan: 0}}, timecode: "00:00:00:25"}' \
  4 cues.rest.timecode
# One frame starts one cue (two cues on it were both taken).
bad_cues $'idle: rest\nltc: {fps: 25}\ncues:\n  rest: {play: {pose: {eye_pan: 0}}, timecode: "00:00:01:00"}\n  b: {play: {pose: {eye_pan: 5}}, timecode: "00:00:01:00"}' \
  5 cues.b.timecode

PYTHONPATH="$root/tests/cli" /usr/bin/python3 - "$tmp/ltc.wav" <<'PY' || fail "the LTC writer"
import sys
from ltc_wav import LtcWriter
w = LtcWriter(25)
w.frames((0, 0, 0, 0), 25)     # 1 s from 00:00:00:00
w.frames((0, 10, 0, 0), 15)    # the jump
w.silence(10)                  # the dropout
w.frames((0, 10, 1, 0), 10)    # where the freewheeling clock said
w.write(sys.argv[1])
PY
cat > "$tmp/cues.yaml" <<YAML
idle: rest
crossfade_s: 0.3
ltc: {fps: 25, freewheel_s: 0.5}
cues:
  rest: {play: {pose: {eye_pan: 0}}}
  a: {play: {pose: {eye_pan: 10}}, timecode: "00:00:00:10"}
  b: {play: {pose: {eye_pan: -10}}, timecode: "00:09:59:00"}
  c: {play: {pose: {eye_pan: 5}}, timecode: "00:10:00:20"}
  d: {play: {pose: {eye_pan: 7}}, timecode: "00:20:00:00"}
YAML
"$animrt" serve "$robot" --cues "$tmp/cues.yaml" --backend sim --no-realtime --no-osc \
  --ltc "$tmp/ltc.wav" --duration 3.2 > "$tmp/out.txt" 2> "$tmp/err.txt"
code=$?
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code: $out $(cat "$tmp/err.txt")"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no torque off: $(cat "$tmp/err.txt")"
grep -qE "^ltc: (49|50) frames, 1 jumps \(re-synced\), 2 dropouts \(freewheeled\), 1 lost, 0 malformed, 3 cues asked$" \
  <<<"$out" || fail "$(grep '^ltc' <<<"$out")"
grep -qE "^cues started: rest 1 a 1 b 1 c 1 d 0$" <<<"$out" || fail "$(grep '^cues started' <<<"$out")"
echo "ok: serve chases LTC"
