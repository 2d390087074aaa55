#!/usr/bin/env bash
# The dashboard's API asks a served figure for cues: a known cue plays, an
# unknown one is refused (400), a control without the token is refused (401),
# and its stop ramps the figure home.
set -uo pipefail
animrt=$1
root=$2
source "$root/tests/cli/serve.bash"

start_serve "$root/configs/robots/animatronic.yaml" --cues "$root/configs/cues/animatronic.yaml" \
  --backend sim --lockstep --no-realtime --no-osc --no-artnet --dashboard 127.0.0.1:0
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "no dashboard line: '$line'"
/usr/bin/python3 - "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" <<'PY' || fail "the dashboard's answers"
import json, sys, time, urllib.error, urllib.request
url, token = sys.argv[1], sys.argv[2]
def post(path, body, with_token=True):
    req = urllib.request.Request(url + path, data=json.dumps(body).encode(), method="POST")
    if with_token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
assert post("/api/cue", {"cue": "look_left"}) == 200
assert post("/api/cue", {"cue": "nothere"}) == 400
assert post("/api/cue", {"cue": "hello"}, with_token=False) == 401
assert post("/api/cue", {"pause": True}) == 200
assert post("/api/cue", {"pause": "yes"}) == 400
assert post("/api/cue", {"cue": "hello", "pause": True}) == 400  # which one is meant?
time.sleep(0.5)
assert post("/api/stop", {}) == 200
PY
wait_exit
out=$(cat "$tmp/out.txt")
[[ $code == 0 ]] || fail "exit $code: $out"
grep -q "ended by stop request" <<<"$out" || fail "not stopped: $out"
grep -q "deactivate: torque off" "$tmp/err.txt" || fail "no torque off: $(cat "$tmp/err.txt")"
grep -qE "^cues started: sway 1 hello 0 look_left 1 greet 0$" <<<"$out" ||
  fail "expected look_left once: $(grep '^cues started' <<<"$out")"
grep -qE "^cue requests: 1 posted, 1 taken" <<<"$out" || fail "$(grep '^cue requests' <<<"$out")"
echo "ok: the dashboard asks for cues"
