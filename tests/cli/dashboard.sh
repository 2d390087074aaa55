#!/usr/bin/env bash
# animrt run --dashboard: a non-loopback address without --dashboard-remote
# is a usage error; otherwise the one startup line comes first on stdout and
# its URL's token stops the run through the ramp (and nothing else does).
# animrt herd --dashboard: the same rules, a herd's info, and a stop with
# the token ends the herd (at real time it would run on for 30 s).
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
robot=$root/configs/robots/quadruped.yaml

"$animrt" run "$robot" --lockstep --duration 1 --dashboard 0.0.0.0:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "a non-loopback dashboard without --dashboard-remote was not a usage error"
grep -q "dashboard-remote" "$tmp/e" || fail "the message does not name --dashboard-remote: $(cat "$tmp/e")"
"$animrt" run "$robot" --lockstep --duration 1 --dashboard 127.0.0.1 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "--dashboard without a port was not a usage error"

"$animrt" run "$robot" --lockstep --no-realtime --dashboard 127.0.0.1:0 \
  > "$tmp/out.txt" 2> "$tmp/err.txt" &
pid=$!
for _ in $(seq 1 200); do
  [[ -s $tmp/out.txt ]] && break
  sleep 0.05
done
line=$(head -n 1 "$tmp/out.txt")
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "first line is not the dashboard's: '$line'"
base=${BASH_REMATCH[1]}
token=${BASH_REMATCH[2]}
/usr/bin/python3 - "$base" "$token" <<'PY' || fail "the dashboard did not answer as it should"
import json, sys, time, urllib.request, urllib.error
base, token = sys.argv[1], sys.argv[2]
info = json.load(urllib.request.urlopen(base + "/api/info"))
assert info["robot"] == "quadruped" and len(info["joints"]) == 12, info
assert info["model"] is not None and info["model"]["bodies"][0]["name"] == "torso"
def post(path, token):
    req = urllib.request.Request(base + path, data=b"{}", method="POST")
    if token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
assert post("/api/stop", None) == 401
assert post("/api/stop", "0" * 32) == 401
time.sleep(0.3)
assert json.load(urllib.request.urlopen(base + "/api/state"))["phase"] != "ended"
assert post("/api/stop", token) == 200
PY
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "the stopped run exited $rc: $(cat "$tmp/err.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "summary: $(cat "$tmp/out.txt")"
[[ $(grep -c "^dashboard:" "$tmp/out.txt") -eq 1 ]] || fail "more than one dashboard line"
herd=$root/configs/herd/gate.yaml
"$animrt" herd "$herd" --quiet --duration 1 --dashboard 0.0.0.0:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "herd: a non-loopback dashboard without --dashboard-remote was not a usage error"
"$animrt" herd "$herd" --quiet --duration 30 --dashboard 127.0.0.1:0 > "$tmp/herd.txt" 2>&1 &
pid=$!
for _ in $(seq 1 200); do
  [[ -s $tmp/herd.txt ]] && break
  sleep 0.05
done
line=$(head -n 1 "$tmp/herd.txt")
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "herd: first line is not the dashboard's: '$line'"
/usr/bin/python3 - "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" <<'PY' || fail "the herd's dashboard did not answer as it should"
import json, sys, urllib.request, urllib.error
base, token = sys.argv[1], sys.argv[2]
info = json.load(urllib.request.urlopen(base + "/api/info"))
assert info["kind"] == "herd" and info["agents"] == 8, info
assert len(json.load(urllib.request.urlopen(base + "/api/state"))["agents"]) == 8
def post(path, token):
    req = urllib.request.Request(base + path, data=b"{}", method="POST")
    if token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
assert post("/api/stop", None) == 401
assert post("/api/stop", token) == 200
PY
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "the stopped herd exited $rc: $(cat "$tmp/herd.txt")"
grep -q "stopped from the dashboard" "$tmp/herd.txt" || fail "herd summary: $(cat "$tmp/herd.txt")"
echo ok
