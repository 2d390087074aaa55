#!/usr/bin/env bash
# The falls summary behind the Table 5 comparison (scripts/experiments/
# summarise.py, falls.md) against an example worked by hand.
set -uo pipefail
root=$2
/usr/bin/python3 "$root/tests/experiments/summarise_test.py" 2>&1 || { echo "FAIL: summarise"; exit 1; }
echo "summarise: ok"
