#!/usr/bin/env bash
# The dashboard page in headless Chromium against a real run: joint names,
# live values, manual jog, a bus fault, the end of the run, no script or
# console errors. Screenshots go to BUILD/browser/.
set -uo pipefail
animrt=$1
root=$2
out="$(cd "$(dirname "$animrt")/.." && pwd)/browser"
exec /usr/bin/python3 "$root/tests/browser/dashboard_browser.py" --animrt "$animrt" --root "$root" --out "$out"
