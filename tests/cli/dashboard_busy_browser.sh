#!/usr/bin/env bash
# The run page open in headless Chromium for a 30 s real-time run with the
# simulated servos' 0.1 s watchdog as shipped: no device faults (read from
# the run's summary).
set -uo pipefail
animrt=$1
root=$2
out="$(cd "$(dirname "$animrt")/.." && pwd)/browser"
exec /usr/bin/python3 "$root/tests/browser/dashboard_busy_run.py" --animrt "$animrt" --root "$root" --out "$out"
