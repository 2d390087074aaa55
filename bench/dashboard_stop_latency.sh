#!/usr/bin/env bash
# Stop latency of the dashboard: a run with --dashboard, then
# tests/cli/dashboard_control_path.py --bench times one POST /api/stop (token,
# no body) with 0 streams, 50 streams, and 50 streams plus 50 connections
# sending their headers a byte at a time. Each case is a fresh run, REPEAT
# times. Usage: bench/dashboard_stop_latency.sh BUILD/bin/animrt [REPEAT [--json-body]]
set -uo pipefail
animrt=$1
repeat=${2:-5}
body=${3:-}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill $pid 2>/dev/null; rm -rf "$tmp"' EXIT
ulimit -n 4096
for case in "0 0" "50 0" "50 50"; do
  read -r streams slow <<< "$case"
  for _ in $(seq 1 "$repeat"); do
    "$animrt" run "$root/configs/robots/quadruped.yaml" --lockstep --no-realtime \
      --dashboard 127.0.0.1:0 > "$tmp/out.txt" 2> /dev/null &
    pid=$!
    for _ in $(seq 1 600); do
      [[ -s $tmp/out.txt ]] && break
      sleep 0.05
    done
    line=$(head -n 1 "$tmp/out.txt")
    [[ $line =~ :([0-9]+)/\?token=([0-9a-f]{32})$ ]] || { echo "no dashboard line"; exit 1; }
    timeout 60 /usr/bin/python3 "$root/tests/cli/dashboard_control_path.py" --bench $body \
      --streams "$streams" --slow "$slow" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}"
    kill "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    pid=""
  done
done
