#!/usr/bin/env bash
# Runs every libFuzzer harness of a fuzz build (make fuzz / make test-fuzz)
# for SECONDS each, one per core at a time, from its seed corpus
# (tests/fuzz/corpus/<name>) plus what earlier runs found
# (BUILD/fuzz-corpus/<name>). A crash, hang (10 s per input), leak or
# sanitizer report fails the run; the input is left in BUILD/fuzz-artifacts.
# Usage: scripts/run-fuzz.sh BUILD SECONDS [HARNESS...]
set -euo pipefail
build=${1:?usage: run-fuzz.sh BUILD SECONDS [HARNESS...]}
seconds=${2:?usage: run-fuzz.sh BUILD SECONDS [HARNESS...]}
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -gt 0 ]; then
  harnesses=("$@")
else
  harnesses=()
  for f in "$root"/tests/fuzz/*.cpp; do harnesses+=("$(basename "$f" .cpp)"); done
fi
mkdir -p "$build/fuzz-artifacts" "$build/fuzz-logs"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# One harness: its table row, and on failure the lines of its log that say
# why, in BUILD/fuzz-logs/<name>.result.
run_one() {
  local name=$1
  local bin="$build/bin/animrt_fuzz_$name"
  local log="$build/fuzz-logs/$name.log"
  local status=ok execs rate units
  mkdir -p "$build/fuzz-corpus/$name"
  if ! "$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$build/fuzz-artifacts/$name-" \
      "$build/fuzz-corpus/$name" "$root/tests/fuzz/corpus/$name" >"$log" 2>&1; then
    status=FAILED
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  units=$(find "$build/fuzz-corpus/$name" -type f | wc -l)
  printf '%-20s %10s %8s %6s  %s\n' "$name" "${execs:-?}" "${rate:-?}" "$units" "$status"
  if [ "$status" != ok ]; then
    grep -E 'ERROR|SUMMARY|Test unit written|runtime error|uncaught|what\(\)' "$log" | head -20 || true
    echo "full log: $log"
  fi
}

# Harnesses run FUZZ_JOBS at a time (default: one per core), each for the
# full SECONDS of wall time on a core of its own: the same fuzzing per
# harness as one after the other, in a fraction of the time.
jobs=${FUZZ_JOBS:-$(nproc)}
running=0
for name in "${harnesses[@]}"; do
  run_one "$name" >"$build/fuzz-logs/$name.result" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait
failed=0
printf '%-20s %10s %8s %6s  %s\n' harness executions exec/s corpus result
for name in "${harnesses[@]}"; do
  cat "$build/fuzz-logs/$name.result"
  if grep -q " FAILED$" "$build/fuzz-logs/$name.result"; then failed=1; fi
done
exit $failed
