#!/usr/bin/env bash
# animrt run --record: the MCAP file read back by an independent reader (the
# MCAP project's @mcap/core from npm, tests/mcap_reader) and checked against
# the run's CSV and summary; animrt view refuses a recording cut short with
# one error naming the file.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

reader="$root/tests/mcap_reader"
[[ -d $reader/node_modules/@mcap/core ]] \
  || fail "no @mcap/core in $reader/node_modules (scripts/install-deps.sh runs npm ci there)"

"$animrt" run "$root/configs/robots/quadruped.yaml" --backend sim --lockstep --duration 0.5 \
  --telemetry "$tmp/t.csv" --record "$tmp/r.mcap" --summary-json "$tmp/s.json" \
  > "$tmp/out.txt" 2> "$tmp/err.txt" || fail "run failed: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^recording: .* messages to $tmp/r.mcap (0 dropped)" "$tmp/out.txt" \
  || fail "no recording line: $(grep -i record "$tmp/out.txt")"
node "$reader/read_back.js" "$tmp/r.mcap" "$tmp/t.csv" "$tmp/s.json" || fail "read back"

# A stop request is in /events at its cycle, before the run's end (on the
# simulated clock, so a busy machine cannot fault the run before the stop).
"$animrt" run "$root/configs/robots/quadruped.yaml" --backend sim --lockstep \
  --record "$tmp/stop.mcap" > "$tmp/stop.txt" 2>&1 &
run_pid=$!
for _ in $(seq 100); do
  grep -q "activate: torque on" "$tmp/stop.txt" && break
  sleep 0.1
done
sleep 0.5
kill -INT $run_pid
wait $run_pid
node "$reader/events.js" "$tmp/stop.mcap" > "$tmp/events.txt" || fail "events: $(cat "$tmp/events.txt")"
grep -q "^2 stop requested" "$tmp/events.txt" || fail "no stop request: $(cat "$tmp/events.txt")"
tail -1 "$tmp/events.txt" | grep -q "^2 run ended: stop request" || fail "end: $(cat "$tmp/events.txt")"

# Cut short: the file ends in the middle of its data.
head -c $(($(stat -c %s "$tmp/r.mcap") / 2)) "$tmp/r.mcap" > "$tmp/cut.mcap"
timeout 10 "$animrt" view "$tmp/cut.mcap" > "$tmp/view.txt" 2>&1
code=$?
[[ $code -ne 0 && $code -ne 124 ]] || fail "view of a truncated file: exit $code"
[[ $(wc -l < "$tmp/view.txt") -eq 1 ]] || fail "not one line: $(cat "$tmp/view.txt")"
grep -q "cut.mcap.*truncated" "$tmp/view.txt" || fail "unclear error: $(cat "$tmp/view.txt")"
# A recording that cannot reach the disk is said so, and the run exits 6.
"$animrt" run "$root/configs/robots/quadruped.yaml" --backend sim --lockstep --duration 0.3 \
  --record /dev/full > "$tmp/full.txt" 2>&1
code=$?
[[ $code -eq 6 ]] || fail "recording to /dev/full: exit $code"
grep -q "^RECORD LOST recording: .* /dev/full: No space left on device" "$tmp/full.txt" \
  || fail "no RECORD LOST line: $(grep -i record "$tmp/full.txt")"
echo "ok"
