#!/usr/bin/env bash
# animrt serve --summary-json: the run's summary and the cues' counts as
# JSON (a lockstep serve of the head with its cues, idling),
# a file that cannot be written refused before anything moves, and one
# that fails when written (a full disk) reported as a lost record, exit 6.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$animrt" serve "$root/configs/robots/head.yaml" --cues "$root/configs/cues/head.yaml" \
  --lockstep --duration 3 --no-osc --no-artnet --summary-json "$tmp/s.json" 2>&1) ||
  fail "serve: exit $?: $out"
/usr/bin/python3 - "$tmp/s.json" <<'PY' || fail "summary JSON: $(cat "$tmp/s.json")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["cycles"] > 300 and j["motion_time_s"] == 3.0, (j["cycles"], j["motion_time_s"])
# Only the idle cue began (once: it repeats without beginning again).
assert j["cues_started"] == {"rest": 1, "nod": 0, "shake": 0, "gasp": 0, "talk": 0}, j["cues_started"]
assert j["cue_requests"]["posted"] == 0, j["cue_requests"]
PY

out=$("$animrt" serve "$root/configs/robots/head.yaml" --cues "$root/configs/cues/head.yaml" \
  --lockstep --duration 1 --no-osc --no-artnet --summary-json "$tmp/no/such/dir/s.json" 2>&1)
code=$?
[[ $code -eq 1 && $out == *"--summary-json: $tmp/no/such/dir/s.json: its folder \"$tmp/no/such/dir\" does not exist"* ]] ||
  fail "unwritable summary: exit $code: $out"
[[ $out != *"start ramp"* && $out != *"cues started"* ]] || fail "it moved first: $out"

out=$("$animrt" serve "$root/configs/robots/head.yaml" --cues "$root/configs/cues/head.yaml" \
  --lockstep --duration 1 --no-osc --no-artnet --summary-json /dev/full 2>&1)
code=$?
[[ $code -eq 6 ]] || fail "summary JSON to /dev/full: exit $code, expected 6: $out"
grep -q "^RECORD LOST summary JSON: could not be written to /dev/full: No space left on device$" \
  <<< "$out" || fail "summary JSON to /dev/full: $out"
echo ok
