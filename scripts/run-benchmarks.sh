#!/usr/bin/env bash
# Runs every benchmark and keeps the output in BUILD/bench/ (the README's
# figures come from these files).
set -euo pipefail
build=${1:-build}
mkdir -p "$build/bench"
for b in "$build"/bin/bench_*; do
  name=$(basename "$b")
  echo "== $name"
  "$b" | tee "$build/bench/$name.txt"
done
