#!/usr/bin/env bash
# Reruns the grammar comparison of Murphy, O'Neill and Carr (their Table 5,
# and Table 4's two strategies) on the horse model with fewer runs, a smaller
# population and fewer generations, and writes the table and plots.
#
#   scripts/experiments/table5.sh [BUILD_DIR] [OUT_DIR]
#   RUNS=3 POPULATION=20 GENERATIONS=10 THREADS=2 scripts/experiments/table5.sh build out
#
# Output: OUT_DIR/table.md (mean and standard deviation over runs of the
# last generation's best and average fitness), OUT_DIR/best.svg and
# OUT_DIR/average.svg (mean over runs, per generation; gnuplot if present),
# and every run's gait, CSV and plot.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-$root/build}"
out="${2:-$root/build/table5}"
runs="${RUNS:-3}"
population="${POPULATION:-20}"
generations="${GENERATIONS:-10}"
threads="${THREADS:-0}"
grammars="${GRAMMARS:-hybrid concatenating sinusoidal numerical free concatenating_varying_weights concatenating_varying_freedom}"
mkdir -p "$out"
for g in $grammars; do
  for ((r = 1; r <= runs; r++)); do
    echo "== horse_$g run $r/$runs"
    "$build/bin/animrt" evolve "$root/configs/evolve/horse_$g.yaml" --out "$out/${g}_$r.yaml" \
      --seed "$r" --population "$population" --generations "$generations" --threads "$threads" \
      --quiet
  done
done
/usr/bin/python3 "$root/scripts/experiments/summarise.py" "$out" "$runs" $grammars
