#!/usr/bin/env bash
# The dashboard's other pages in headless Chromium: a show's play, pause and
# seek, the replay of `animrt view`, a herd from above and an evolve run's
# curves, figure and stop; no script or console errors. Screenshots go to
# BUILD/browser/.
set -uo pipefail
animrt=$1
root=$2
out="$(cd "$(dirname "$animrt")/.." && pwd)/browser"
exec /usr/bin/python3 "$root/tests/browser/dashboard_pages.py" --animrt "$animrt" --root "$root" --out "$out"
