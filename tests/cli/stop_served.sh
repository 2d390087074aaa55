#!/usr/bin/env bash
# The commands that serve a dashboard and may be left running, animrt herd
# and animrt evolve with --dashboard, end on a stop signal (not only Ctrl-C)
# as on the page's Stop: exit 0, every file written whole, never killed
# half-way.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# Waits until the file has at least N lines.
wait_lines() {
  for _ in $(seq 1 600); do
    [[ $(wc -l < "$1") -ge $2 ]] && return 0
    kill -0 $pid 2> /dev/null || break
    sleep 0.05
  done
  fail "$1: fewer than $2 lines: $(cat "$1")"
}

"$animrt" herd "$root/configs/herd/gate.yaml" --duration 30 --out "$tmp/herd.csv" \
  --dashboard 127.0.0.1:0 > "$tmp/herd.txt" 2>&1 &
pid=$!
wait_lines "$tmp/herd.txt" 2
sleep 1
kill -HUP $pid
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "herd on SIGHUP: exit $rc: $(cat "$tmp/herd.txt")"
grep -q "stopped by a signal" "$tmp/herd.txt" || fail "herd on SIGHUP: $(cat "$tmp/herd.txt")"
grep -q "^wrote $tmp/herd.csv$" "$tmp/herd.txt" || fail "herd on SIGHUP: no CSV: $(cat "$tmp/herd.txt")"
/usr/bin/python3 - "$tmp/herd.csv" <<'PY' || fail "herd on SIGHUP: the CSV is not whole"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
assert len(rows) > 2 and all(len(r) == len(rows[0]) for r in rows), (len(rows), rows[-1])
PY

cat > "$tmp/evolve.yaml" <<EOF
name: stop_served
grammar: $root/configs/grammars/quadruped_sinusoidal.bnf
model: $root/configs/models/quadruped.xml
seed_gait: $root/configs/gaits/quadruped_seed.yaml
search: {seed: 3, population: 10, generations: 1000, elites: 2, max_depth: 6}
walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}
EOF
"$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/gait.yaml" --threads 1 --dashboard 127.0.0.1:0 \
  > "$tmp/evolve.txt" 2>&1 &
pid=$!
wait_lines "$tmp/evolve.txt" 4  # the dashboard, the search, two generations
kill -USR1 $pid
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "evolve on SIGUSR1: exit $rc: $(cat "$tmp/evolve.txt")"
last=$(sed -n 's/^stopped by a signal after generation \([0-9]*\) of 1000$/\1/p' "$tmp/evolve.txt")
[[ -n $last ]] || fail "evolve on SIGUSR1: no stop line: $(cat "$tmp/evolve.txt")"
for f in gait.yaml gait.csv gait.svg; do
  [[ -s $tmp/$f ]] || fail "evolve on SIGUSR1: $f not written after the stop"
done
[[ $(wc -l < "$tmp/gait.csv") -eq $((last + 2)) ]] ||
  fail "evolve on SIGUSR1: the CSV has $(wc -l < "$tmp/gait.csv") lines after a stop at generation $last"
echo "stop_served: ok"
