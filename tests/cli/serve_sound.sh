#!/usr/bin/env bash
# `animrt serve` plays a cue's sound track: the simulated head,
# its cues' sound written as a sound card would play it (--audio-device
# file:FOLDER). Asked for over OSC, the talking cue's track sounds from its
# start, in order; the switch to the idle cue cuts it, and it stays silent.
set -uo pipefail
animrt=$1
root=$2
here=$(dirname "$0")
source "$root/tests/cli/serve.bash"

# A 4-second track whose every sample is its own frame number (s16), so what
# was heard tells which part of the track it was.
/usr/bin/python3 - "$tmp/talk.wav" <<'PY' || fail "could not write the track"
import struct, sys, wave
with wave.open(sys.argv[1], "wb") as w:
    w.setnchannels(1); w.setsampwidth(2); w.setframerate(8000)
    w.writeframes(b"".join(struct.pack("<h", k + 1) for k in range(32000)))
PY
cat > "$tmp/talk.yaml" <<'YAML'
audio: {file: talk.wav}
joints:
  jaw: {keys: [[0, 0], [1, 20], [2, 0], [3, 20], [4, 0]]}
YAML
cat > "$tmp/cues.yaml" <<'YAML'
idle: rest
cues:
  rest: {play: {pose: {jaw: 0}}}
  talk: {play: {show: talk.yaml}, crossfade_s: 0.3}
YAML
mkdir "$tmp/sound"

start_serve "$root/configs/robots/head.yaml" --cues "$tmp/cues.yaml" --backend sim \
  --no-realtime --osc-port 0 --no-artnet --audio-device "file:$tmp/sound"
[[ $line =~ ^osc:\ listening\ on\ 127\.0\.0\.1:([0-9]+)$ ]] || fail "no OSC line: '$line'"
port=${BASH_REMATCH[1]}
grep -q "audio: $tmp/talk.wav starts at show time 0 s" "$tmp/err.txt" ||
  fail "the cue's sound track was not opened: $(cat "$tmp/err.txt")"
# The start ramp (1.5 s) is over before the first trigger (a cue asked for and
# replaced before the motion starts never plays).
/usr/bin/python3 "$here/osc_send.py" "$port" "sleep 2.0
send /cue/talk
sleep 1.0
send /cue/rest
sleep 0.6
send /stop" > /dev/null || fail "the sender failed"
wait_exit
[[ $code == 0 ]] || fail "exit $code: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -qE "^cues started: rest 2 talk 1$" "$tmp/out.txt" ||
  fail "$(grep '^cues started' "$tmp/out.txt")"

/usr/bin/python3 - "$tmp/sound/talk.s16" <<'PY' || fail "the sound heard is not the cue's"
import struct, sys
data = open(sys.argv[1], "rb").read()
s = struct.unpack("<%dh" % (len(data) // 2), data)
heard = [k for k, v in enumerate(s) if v != 0]
assert heard, "nothing was heard (%d samples of silence)" % len(s)
first, last = heard[0], heard[-1]
sound = s[first:last + 1]
print("silence %.3f s, sound %.3f s (track %d..%d), silence %.3f s" %
      (first / 8000, len(sound) / 8000, sound[0], sound[-1], (len(s) - last - 1) / 8000))
# From the track's start (within the time the player takes to hear the cue),
# in order: the track's frames only ever go forward.
assert 0 < sound[0] <= 800, sound[0]
assert all(v != 0 for v in sound), "a gap in the sound"
assert all(b >= a for a, b in zip(sound, sound[1:])), "the sound went back"
# Cut by the switch, 1 s in (well before the track's end), and silent after it.
assert 0.5 < len(sound) / 8000 < 2.0, len(sound) / 8000
assert (len(s) - last - 1) / 8000 > 0.3, "not silent after the switch"
PY
echo "ok: serve plays a cue's sound track and cuts it at the switch"
