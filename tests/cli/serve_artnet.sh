#!/usr/bin/env bash
# `animrt serve` triggered over Art-Net by a sender written from the Art-Net
# specification's ArtDmx layout: the cue file's DMX channel selects cues by
# value, ArtDmx packets whose length disagrees with their header are counted
# and dropped, other packets and universes are ignored, and SIGTERM stops the
# figure with its ramp home. A bad cue file stops everything before it starts.
set -uo pipefail
animrt=$1
root=$2
source "$root/tests/cli/serve.bash"

bad_cues $'idle: rest\ncues:\n  rest: {play: {pose: {neck_pan: 0}}, dmx: 300}' 3 cues.rest.dmx

start_serve "$root/configs/robots/animatronic.yaml" --cues "$root/configs/cues/animatronic.yaml" \
  --backend sim --lockstep --no-realtime --no-osc --artnet-port 0
[[ $line =~ ^artnet:\ listening\ on\ 127\.0\.0\.1:([0-9]+)\ for\ universe\ 0,\ channel\ 1$ ]] ||
  fail "no Art-Net line: '$line'"
/usr/bin/python3 - "${BASH_REMATCH[1]}" <<'PY' || fail "the sender failed"
# ArtDmx: ID "Art-Net\0", OpCode 0x5000 little-endian, ProtVerHi 0, ProtVerLo
# 14, Sequence, Physical, SubUni, Net, Length big-endian (1-512, even as a sender should), Data.
import socket, struct, sys, time
sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
target = ("127.0.0.1", int(sys.argv[1]))
def artdmx(values, universe=0, length=None, data_len=None):
    data = bytes(values) + bytes(max(0, 2 - len(values)))
    if len(data) % 2:
        data += b"\0"
    length = len(data) if length is None else length
    if data_len is not None:
        data = data[:data_len]
    return (b"Art-Net\0" + struct.pack("<H", 0x5000) + bytes([0, 14, 1, 0]) +
            bytes([universe & 0xff, universe >> 8]) + struct.pack(">H", length) + data)
send = lambda p: sock.sendto(p, target)
for _ in range(3):
    send(artdmx([3, 0]))        # look_left, every frame as a desk repeats it
    time.sleep(0.05)
time.sleep(0.5)
send(artdmx([2], universe=1))   # another universe: ignored
send(b"Art-Net\0" + struct.pack("<H", 0x2000) + bytes([0, 14, 0, 0]))  # ArtPoll: ignored
send(artdmx([2, 0], length=4))  # says 4 channels, carries 2
send(artdmx([2, 0, 0, 0, 0], length=3))  # says 3 channels, carries 6
send(artdmx([2, 0])[:17])       # cut inside the header
send(artdmx([0, 0]))            # zero: no cue
time.sleep(0.2)
send(artdmx([9, 0]))            # a value no cue has: counted
time.sleep(0.2)
send(artdmx([4, 0]))            # greet
time.sleep(0.5)
old = artdmx([2, 0])
send(old[:10] + bytes([0, 0]) + old[12:])  # protocol version 0: dropped
# A second desk asking for hello while the first still holds greet: merged,
# the higher level wins (greet stays).
second = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
second.bind(("127.0.0.2", 0))
for _ in range(3):
    second.sendto(artdmx([2, 0]), target)
    time.sleep(0.05)
time.sleep(0.3)
PY
kill -TERM $pid
wait_exit
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code: $out"
grep -q "ended by stop request" <<<"$out" || fail "SIGTERM did not stop: $out"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no torque off: $(cat "$tmp/err.txt")"
grep -qE "^artnet: 15 packets, 9 frames of the cue universe, 4 malformed, 0 out of sequence, 2 ignored, 1 values asking for no cue$" <<<"$out" ||
  fail "$(grep '^artnet' <<<"$out")"
grep -qE "^cues started: sway [1-9][0-9]* hello 0 look_left 1 greet 1$" <<<"$out" ||
  fail "expected look_left and greet once: $(grep '^cues started' <<<"$out")"
echo "ok: serve over Art-Net"
