#!/usr/bin/env bash
# `animrt serve` driven by a lighting desk over sACN (E1.31) and Art-Net,
# from senders written from the standards' packet layouts: an sACN channel
# selects cues (unicast and the universe's multicast group), the standard's
# arbitration holds (late sequence numbers, lower priorities, preview data
# are not output), malformed packets are counted; 16-bit (sACN) and 8-bit
# (Art-Net) channels drive joints, measured on the simulated servos; when the
# streams stop the joints hold, then ease home. Bad sACN keys stop
# everything before it starts.
set -uo pipefail
animrt=$1
root=$2
source "$root/tests/cli/serve.bash"
robot="$root/configs/robots/animatronic.yaml"

cues='cues:
  rest: {play: {pose: {eye_pan: 0}}, dmx: 1}'
bad_cues "idle: rest
sacn: {universe: 0, channel: 1}
$cues" 2 "sacn.universe"
bad_cues "idle: rest
sacn: {universe: 1, joints: {neck_pan: {channel: 4, fine: 4}}}
$cues" 2 "sacn.joints.neck_pan.fine"
bad_cues "idle: rest
artnet: {universe: 0, joints: {neck_pan: {channel: 4, range: [-90, 0]}}}
$cues" 2 "artnet.joints.neck_pan.range"
bad_cues "idle: rest
sacn: {universe: 1, joints: {nose: {channel: 4}}}
$cues" 2 "sacn.joints.nose"

cat > "$tmp/cues.yaml" <<YAML
idle: rest
crossfade_s: 0.3
sacn: {universe: 7, channel: 1, joints: {neck_pan: {channel: 2, fine: 3, range: [-40, 40]}}, hold_s: 1.5}
artnet: {universe: 0, joints: {neck_tilt: {channel: 5}}, hold_s: 1.5}
cues:
  rest: {play: {pose: {eye_pan: 0}}, dmx: 1}
  left: {play: {pose: {eye_pan: 10}}, dmx: 2}
  right: {play: {pose: {eye_pan: -10}}, dmx: 3}
YAML
serve_in_background "$robot" --cues "$tmp/cues.yaml" --backend sim --no-realtime --no-osc \
  --artnet-port 0 --sacn-port 0 --sacn-multicast --dashboard 127.0.0.1:0
await_line "^dashboard:" "$tmp/out.txt"
artnet=$(sed -n 's/^artnet: listening on 127\.0\.0\.1:\([0-9]*\) for universe 0, 1 joint(s)$/\1/p' "$tmp/out.txt")
sacn=$(sed -n 's/^sacn: listening on 127\.0\.0\.1:\([0-9]*\) for universe 7, channel 1, 1 joint(s)$/\1/p' "$tmp/out.txt")
url=$(sed -n 's|^dashboard: \(http://127\.0\.0\.1:[0-9]*\)/.*|\1|p' "$tmp/out.txt")
[[ -n $artnet && -n $sacn && -n $url ]] || fail "serve did not start: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^sacn: joined 239.255.0.7$" "$tmp/out.txt" || fail "no multicast group: $(cat "$tmp/out.txt")"

PYTHONPATH="$root/tests/cli" /usr/bin/python3 - "$sacn" "$artnet" "$url" <<'PY' || fail "the desk's test"
import json, math, socket, struct, sys, time, urllib.request
from sacn_send import Sender, data_packet
sacn = Sender(int(sys.argv[1]))
artnet_port, url = int(sys.argv[2]), sys.argv[3]
art = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
def artdmx(values):  # ID, OpCode 0x5000 LE, version 14, sequence, physical, port address, length BE
    data = bytes(values)
    return (b"Art-Net\0" + struct.pack("<H", 0x5000) + bytes([0, 14, 0, 0, 0, 0]) +
            struct.pack(">H", len(data)) + data)
def measured(name):
    state = json.load(urllib.request.urlopen(url + "/api/state"))
    return math.degrees(next(j["meas"] for j in state["joints"] if j["name"] == name))
def wait_for(name, deg, seconds, send=None):
    end = time.time() + seconds
    while time.time() < end:
        if send: send()
        if abs(measured(name) - deg) < 1.5: return True
        time.sleep(0.04)
    return False
# +30 degrees in [-40, 40] on 16 bits: (30 + 40) / 80 * 65535
level = round(70 / 80 * 65535)
seq = [0]
def frame(cue=2):
    seq[0] += 1
    sacn.multicast(7, data_packet(7, [cue, level >> 8, level & 0xff], seq[0]))
    art.sendto(artdmx([0, 0, 0, 0, 255, 0]), ("127.0.0.1", artnet_port))
assert wait_for("neck_pan", 30.0, 6.0, frame), "neck_pan never reached 30 (%.1f)" % measured("neck_pan")
assert wait_for("neck_tilt", 25.0, 2.0, frame), "neck_tilt never reached 25 (%.1f)" % measured("neck_tilt")
# Not output: a late sequence number, a lower priority, preview data, another
# universe. (The desk's own packets by the group's socket, so in order.)
sacn.multicast(7, data_packet(7, [3, 0, 0], seq[0] - 1))
sacn.unicast(data_packet(7, [3, 0, 0], 1, priority=50, cid=b"\x22" * 16))
sacn.multicast(7, data_packet(7, [3, 0, 0], seq[0] + 1, options=0x80))
sacn.unicast(data_packet(8, [3, 0, 0], 1))
# Malformed: a count that disagrees, a cut packet, a wrong identifier, priority 201.
sacn.unicast(data_packet(7, [3, 0, 0], seq[0] + 2, count=10))
sacn.unicast(data_packet(7, [3, 0, 0], seq[0] + 2)[:100])
sacn.unicast(b"ASC-E1.18" + data_packet(7, [3], 1)[9:])
sacn.unicast(data_packet(7, [3, 0, 0], seq[0] + 2, priority=201))
time.sleep(0.2)
# The streams stop: held, then home.
time.sleep(0.3)
assert abs(measured("neck_pan") - 30.0) < 1.5, "not held: %.1f" % measured("neck_pan")
assert wait_for("neck_pan", 0.0, 8.0), "neck_pan never eased home (%.1f)" % measured("neck_pan")
assert wait_for("neck_tilt", 0.0, 2.0), "neck_tilt never eased home (%.1f)" % measured("neck_tilt")
PY
kill -TERM $pid
wait_exit
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code: $out"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no torque off: $(cat "$tmp/err.txt")"
grep -qE "^sacn: [0-9]+ packets, [0-9]+ frames output, 4 malformed, 1 out of sequence, 3 ignored, 0 values asking for no cue$" <<<"$out" ||
  fail "$(grep '^sacn' <<<"$out")"
grep -qE "^sacn joints: [0-9]+ frames, 1 times lost" <<<"$out" || fail "$(grep '^sacn joints' <<<"$out")"
grep -qE "^artnet joints: [0-9]+ frames, 1 times lost" <<<"$out" || fail "$(grep '^artnet joints' <<<"$out")"
grep -qE "^cues started: rest 1 left 1 right 0$" <<<"$out" || fail "$(grep '^cues started' <<<"$out")"
echo "ok: serve over sACN, DMX joints"
