#!/usr/bin/env bash
# The head (four Dynamixel servos, a jaw whose limits start at 0 deg) brings
# up and speaks its utterance on the simulated servos in lockstep: every
# simulated servo starts inside its joint's limits, so bring-up passes and no
# warning about a joint outside its limits is printed.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$animrt" run "$root/configs/robots/head.yaml" --backend sim --duration 2 --lockstep --no-realtime \
  --no-audio --summary-json "$tmp/s.json" > "$tmp/out.txt" 2>&1 || fail "run failed: $(cat "$tmp/out.txt")"
grep -q "outside its limits" "$tmp/out.txt" && fail "a simulated joint started outside its limits: $(cat "$tmp/out.txt")"
/usr/bin/python3 - "$tmp/s.json" <<'PY' || fail "summary wrong: $(cat "$tmp/out.txt")"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "duration" and s["exit_code"] == 0, (s["end_reason"], s["exit_code"])
assert s["cycles"] >= 200, s["cycles"]  # 2 s at 100 Hz, before the stop ramp
assert len(s["devices"]) == 4 and all(not d["faulted"] for d in s["devices"]), s["devices"]
PY
echo "head_sim: ok"
