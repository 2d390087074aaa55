#!/usr/bin/env bash
# The dashboard's stop cannot be taken away: a DNS name that only looks like
# loopback is refused at startup; a request naming another host (a page
# whose name was rebound to this machine) is refused with 403; with 50 open
# streams (a 51st is refused with 503) and 50 connections sending their
# headers a byte at a time, a stop with the token and no body is answered
# and ends the run; the slow connections are dropped.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
robot=$root/configs/robots/quadruped.yaml

for host in 127.0.0.1.nip.io 127.evil.example; do
  "$animrt" run "$robot" --lockstep --duration 1 --dashboard $host:0 > "$tmp/o" 2> "$tmp/e"
  [[ $? -eq 1 ]] || fail "--dashboard $host:0 was not a usage error"
  grep -q "not a loopback address" "$tmp/e" || fail "$host: $(cat "$tmp/e")"
done

ulimit -n 4096
"$animrt" run "$robot" --lockstep --no-realtime --dashboard 127.0.0.1:0 \
  > "$tmp/out.txt" 2> "$tmp/err.txt" &
pid=$!
for _ in $(seq 1 200); do
  [[ -s $tmp/out.txt ]] && break
  sleep 0.05
done
line=$(head -n 1 "$tmp/out.txt")
[[ $line =~ ^dashboard:\ http://127\.0\.0\.1:([0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "first line is not the dashboard's: '$line'"
/usr/bin/python3 "$root/tests/cli/dashboard_control_path.py" "${BASH_REMATCH[1]}" \
  "${BASH_REMATCH[2]}" || fail "the dashboard did not answer as it should"
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "the stopped run exited $rc: $(cat "$tmp/err.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "summary: $(cat "$tmp/out.txt")"
echo "PASS"
