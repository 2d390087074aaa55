#!/usr/bin/env bash
# The rank test behind the Table 5 comparison (scripts/experiments/ranktest.py)
# against examples worked by hand.
set -uo pipefail
root=$2
/usr/bin/python3 "$root/tests/experiments/ranktest_test.py" 2>&1 || { echo "FAIL: ranktest"; exit 1; }
echo "ranktest: ok"
