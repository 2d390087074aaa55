#!/usr/bin/env bash
# Reruns the grammar comparison of Murphy, O'Neill and Carr (their Table 5,
# and Table 4's two strategies) on the horse model, at the paper's size by
# default, and writes the table, the rank tests of the paper's claims and
# the plots. Never part of the tests: at full size it runs for hours.
#
#   scripts/experiments/table5.sh [BUILD_DIR] [OUT_DIR]
#   RUNS=10 POPULATION=75 GENERATIONS=50 RANKS=2 scripts/experiments/table5.sh build out
#
# Resumable: every finished run leaves OUT_DIR/<grammar>_<run>.{yaml,csv,svg}
# (written under a temporary name, renamed when the run ends; the CSV last),
# and a second call skips the runs whose CSV is there; kill it and start it
# again at will.
#
# RANKS > 1 spreads each run's walks over MPI ranks (mpirun, one thread each;
# MPIRUN_ARGS adds e.g. --hostfile hosts for a cluster); RANKS=1 uses THREADS
# threads (0: all cores). A run's result does not depend on how its walks were
# spread (tests/evolve/cli_test.cpp).
#
# Output: OUT_DIR/table.md (mean and standard deviation over runs of the last
# generation's best and average fitness, beside the paper's), OUT_DIR/ranks.md
# (Mann-Whitney U tests of the paper's claims, and of structured mapping's
# falls against the hybrid's), OUT_DIR/falls.md (falls from
# generation 10 on; the best gaits against the Froude targets), OUT_DIR/best.svg and
# average.svg (gnuplot), OUT_DIR/timing.txt (wall time of every run).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-$root/build}"
out="${2:-$root/build/table5}"
runs="${RUNS:-10}"
population="${POPULATION:-75}"
generations="${GENERATIONS:-50}"  # after the initial one, as in a run file
ranks="${RANKS:-1}"
threads="${THREADS:-0}"
# The paper's seven configurations, then the hybrid grammar with structured
# mapping (ours, beyond the paper: configs/evolve/horse_hybrid_structured.yaml).
grammars="${GRAMMARS:-hybrid concatenating sinusoidal numerical free concatenating_varying_weights concatenating_varying_freedom hybrid_structured}"
mkdir -p "$out"

launch=()
mode=(--threads "$threads")
if [ "$ranks" -gt 1 ]; then
  root_flag=()
  [ "$(id -u)" -eq 0 ] && root_flag=(--allow-run-as-root)
  # shellcheck disable=SC2206
  launch=(mpirun "${root_flag[@]}" --oversubscribe -np "$ranks" ${MPIRUN_ARGS:-})
  mode=(--threads 1 --mpi)
fi

start_all=$(date +%s)
# Run by run across the grammars, so that a comparison stopped early still
# has as many runs of every grammar (give or take one).
for ((r = 1; r <= runs; r++)); do
  for g in $grammars; do
    name="${g}_$r"
    if [ -f "$out/$name.csv" ]; then
      echo "== $name: done earlier, skipped"
      continue
    fi
    echo "== horse_$g run $r/$runs (population $population, $generations generations)"
    t0=$(date +%s)
    tmp="$out/.$name.partial"
    set +e
    "${launch[@]}" "$build/bin/animrt" evolve "$root/configs/evolve/horse_$g.yaml" \
      --out "$tmp.yaml" --csv "$tmp.csv" --plot "$tmp.svg" --seed "$r" \
      --population "$population" --generations "$((generations + 1))" "${mode[@]}" --quiet
    code=$?
    set -e
    # Exit 4: the run ended with no valid individual (no gait); still a result.
    if [ "$code" -ne 0 ] && [ "$code" -ne 4 ]; then
      echo "error: $name failed (exit $code)" >&2
      exit "$code"
    fi
    [ -f "$tmp.svg" ] && mv "$tmp.svg" "$out/$name.svg"
    [ -f "$tmp.yaml" ] && mv "$tmp.yaml" "$out/$name.yaml"
    mv "$tmp.csv" "$out/$name.csv"  # last: its presence marks the run done
    echo "$name $(($(date +%s) - t0)) s" >> "$out/timing.txt"
  done
done
echo "this call: $(($(date +%s) - start_all)) s; every run's time in $out/timing.txt"
POPULATION="$population" /usr/bin/python3 "$root/scripts/experiments/summarise.py" "$out" "$runs" $grammars
