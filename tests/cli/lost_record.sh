#!/usr/bin/env bash
# Output that cannot be written is never a silent success nor a silent death:
# telemetry or a summary JSON that cannot be written ends the run with exit
# 6 and a RECORD LOST line that counts the loss and names the error; a run
# whose stdout and stderr reader went away (`2>&1 | head -1`) ends as after
# a stop request (exit 0), not killed by SIGPIPE.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
robot="$root/configs/robots/quadruped.yaml"

"$animrt" run "$robot" --backend sim --lockstep --duration 0.5 --telemetry /dev/full \
  > "$tmp/out.txt" 2> "$tmp/err.txt"
code=$?
[[ $code == 6 ]] || fail "telemetry to /dev/full: exit $code, expected 6: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -Eq "^RECORD LOST telemetry: ([0-9]+) of \1 records could not be written to /dev/full: No space left on device \(0 written, 0 dropped\)$" \
  "$tmp/out.txt" || fail "telemetry to /dev/full: $(grep -i telemetry "$tmp/out.txt")"
grep -q "ended by duration" "$tmp/out.txt" || fail "a lost record stopped the figure: $(head -2 "$tmp/out.txt")"

"$animrt" run "$robot" --backend sim --lockstep --duration 0.5 --telemetry "$tmp/t.csv" \
  --summary-json /dev/full > "$tmp/out.txt" 2> "$tmp/err.txt"
code=$?
[[ $code == 6 ]] || fail "summary JSON to /dev/full: exit $code, expected 6: $(cat "$tmp/out.txt" "$tmp/err.txt")"
grep -q "^RECORD LOST summary JSON: could not be written to /dev/full: No space left on device$" \
  "$tmp/out.txt" || fail "summary JSON to /dev/full: $(tail -3 "$tmp/out.txt")"
grep -Eq "^telemetry: [0-9]+ records to $tmp/t.csv \(0 dropped\)$" "$tmp/out.txt" ||
  fail "telemetry to a file: $(grep -i telemetry "$tmp/out.txt")"

"$animrt" run "$robot" --backend sim --no-realtime --duration 2 2>&1 | head -1 > "$tmp/first.txt"
codes=("${PIPESTATUS[@]}")
[[ ${codes[0]} == 0 ]] || fail "run piped into head -1: exit ${codes[0]}, expected 0"
grep -q "simulated devices: serial legs" "$tmp/first.txt" || fail "run piped into head -1: $(cat "$tmp/first.txt")"
echo "lost_record: ok"
