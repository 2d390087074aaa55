#!/usr/bin/env bash
# `animrt serve` triggered by a raw MIDI byte stream written into a FIFO, as a
# rawmidi device delivers it: a note on and a program change select cues,
# with running status, real-time bytes interleaved inside messages, a SysEx
# skipped, a note on with velocity 0 (a note off) and notes no cue answers
# counted; stray data bytes counted as malformed. A bad MIDI key in the cue
# file stops everything before it starts. (The ALSA sequencer input needs
# /dev/snd/seq, which this test does not assume.)
set -uo pipefail
animrt=$1
root=$2
source "$root/tests/cli/serve.bash"
robot="$root/configs/robots/animatronic.yaml"

bad_cues $'idle: rest\ncues:\n  rest: {play: {pose: {eye_pan: 0}}, midi: {note: 60}}\n  a: {play: {pose: {eye_pan: 1}}, midi: {note: 60, channel: 2}}' \
  4 cues.a.midi.note

cat > "$tmp/cues.yaml" <<YAML
idle: rest
crossfade_s: 0.2
cues:
  rest: {play: {pose: {eye_pan: 0}}}
  a: {play: {pose: {eye_pan: 10}}, midi: {note: 60, channel: 1}}
  b: {play: {pose: {eye_pan: -10}}, midi: {note: 62}}
  c: {play: {pose: {eye_pan: 5}}, midi: {program: 7, channel: 10}}
YAML
mkfifo "$tmp/midi"
start_serve "$robot" --cues "$tmp/cues.yaml" --backend sim --lockstep --no-realtime --no-osc \
  --midi "$tmp/midi"
grep -q "^midi: reading $tmp/midi$" "$tmp/out.txt" || fail "no MIDI line: $(cat "$tmp/out.txt")"
/usr/bin/python3 - "$tmp/midi" <<'PY' || fail "the MIDI writer"
import os, sys, time
fd = os.open(sys.argv[1], os.O_WRONLY)
def send(*data):
    os.write(fd, bytes(data))
    time.sleep(0.3)
send(0x12, 0x34)                        # data bytes without a status: 2 malformed
send(0x90, 60, 0xF8, 100)               # note on 60, channel 1, a clock byte inside: a
send(0xF0, 0x7E, 0x7F, 0x06, 0x01, 0xF7)  # a SysEx: skipped
send(0x91, 60, 100, 62, 0)              # channel 2 (unbound), running status note off
send(62, 90)                            # running status: note on 62: b
send(0xFE, 0xC9, 7)                     # active sensing, program 7 on channel 10: c
send(0xC0, 7)                           # program 7 on channel 1: unbound
PY
kill -TERM $pid
wait_exit
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code: $out"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no torque off: $(cat "$tmp/err.txt")"
grep -qE "^midi: 6 messages, 3 triggers, 2 unbound, 2 malformed, 0 from unknown ports$" <<<"$out" ||
  fail "$(grep '^midi' <<<"$out")"
grep -qE "^cues started: rest 1 a 1 b 1 c 1$" <<<"$out" || fail "$(grep '^cues started' <<<"$out")"

echo "ok: serve over MIDI"
