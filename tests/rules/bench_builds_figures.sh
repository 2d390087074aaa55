#!/usr/bin/env bash
# Every benchmark and every test that runs a figure builds it with the figure
# builder (runtime/include/animrt/runtime/figure.hpp), so that what a
# benchmark measures or a test checks is what `animrt run` runs, and no
# benchmark reaches into tests/. Fails, naming file and line, on a benchmark
# that assembles a figure by hand: builds a Runner or a RunMonitor, starts
# simulated devices or widens their timeouts itself, or builds the buses of a
# robot file it loaded; and on a test that does the same (the unit tests of
# the runner and the dashboards build a Runner or a RunMonitor of their own,
# around buses of their own: only the integration tests may not; the rig in
# tests/support is built on the builder itself).
#
# Usage: bench_builds_figures.sh SOURCE_DIR
set -u
src=${1:?usage: bench_builds_figures.sh SOURCE_DIR}
problems=""
# FILE PATTERN TEXT WHY: every line of TEXT matching PATTERN is a problem.
check() {
  local hits
  hits=$(grep -nE "$2" <<<"$3" | cut -d: -f1)
  for line in $hits; do problems+="$1:$line: $4"$'\n'; done
}
for file in "$src"/bench/*.cpp; do
  rel=${file#"$src"/}
  # Comments do not count: only code builds a figure.
  code=$(sed -e 's://.*$::' "$file")
  check "$rel" '\bRunner\b|\bRunMonitor\b' "$code" \
    "builds the runner by hand; build the figure with animrt::Figure"
  check "$rel" 'start_simulated_devices|widen_timeouts_for_lockstep|raise_simulated_devices' \
    "$code" "starts a figure's simulated devices by hand; use SimulatedBackend"
  if grep -qE '\bload_robot\(' <<<"$code"; then
    check "$rel" '\bmake_(simulated_)?bus\(' "$code" \
      "builds a robot file's buses or devices by hand; use Figure::bus()"
  fi
  check "$rel" '#include[[:space:]]+"[^"]*tests/' "$(cat "$file")" \
    "includes a file of the tests; share it through a library"
done
while IFS= read -r file; do
  rel=${file#"$src"/}
  code=$(sed -e 's://.*$::' "$file")
  if [[ $rel == tests/integration* ]]; then
    check "$rel" '\bRunner\b|\bRunMonitor\b' "$code" \
      "builds the runner by hand; build the figure with animrt::Figure or test::SimRig"
  fi
  check "$rel" 'start_simulated_devices|widen_timeouts_for_lockstep|raise_simulated_devices' \
    "$code" "starts a figure's simulated devices by hand; use SimulatedBackend"
  if grep -qE '\bload_robot\(' <<<"$code"; then
    check "$rel" '\bmake_(simulated_)?bus\(' "$code" \
      "builds a robot file's buses or devices by hand; use Figure::bus()"
  fi
done < <(find "$src/tests" -name '*.cpp' -not -path "$src/tests/support/*" | sort)
if [ -n "$problems" ]; then
  printf '%s' "$problems"
  echo "FAIL: benchmarks or tests assemble figures by hand (see above)"
  exit 1
fi
echo "ok: every benchmark and test builds its figures with animrt::Figure"
