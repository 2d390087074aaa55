#!/usr/bin/env bash
# Runs every benchmark and keeps the output in BUILD/bench/ (the figures in
# docs/results/ come from these files). cyclictest (rt-tests) first, as the
# machine's own wake-up latency baseline: the loop cannot do better.
set -euo pipefail
build=${1:-build}
mkdir -p "$build/bench"
if command -v cyclictest > /dev/null; then
  echo "== cyclictest (SCHED_FIFO 80, 2 ms interval, 5 s)"
  cyclictest -m -p 80 -i 2000 -l 2500 -q | tee "$build/bench/cyclictest.txt"
fi
for b in "$build"/bin/bench_*; do
  name=$(basename "$b")
  echo "== $name"
  "$b" | tee "$build/bench/$name.txt"
done
