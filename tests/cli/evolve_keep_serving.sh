#!/usr/bin/env bash
# A short animrt evolve --dashboard ends before anyone opens its page: it
# says the page closes and how to keep it; with --keep-serving the page
# shows the ended search until Ctrl-C, and the run then ends with exit 0.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill "$pid" 2> /dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat > "$tmp/evolve.yaml" <<EOF
name: short
grammar: $root/configs/grammars/quadruped_sinusoidal.bnf
model: $root/configs/models/quadruped.xml
seed_gait: $root/configs/gaits/quadruped_seed.yaml
search: {seed: 3, population: 2, generations: 0, elites: 1, max_depth: 6}
walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}
EOF
out=$("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/g.yaml" --threads 1 --quiet \
  --dashboard 127.0.0.1:0 2>&1)
code=$?
[[ $code -eq 0 || $code -eq 4 ]] || fail "evolve exited $code: $out"
[[ $out == *"the search has ended: its dashboard page closes now (--keep-serving keeps it until Ctrl-C)"* ]] ||
  fail "the page closed without a word: $out"

"$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/k.yaml" --threads 1 --quiet \
  --dashboard 127.0.0.1:0 --keep-serving > "$tmp/keep.txt" 2>&1 &
pid=$!
for _ in $(seq 1 600); do
  grep -q "until Ctrl-C" "$tmp/keep.txt" && break
  kill -0 "$pid" 2> /dev/null || fail "evolve --keep-serving ended by itself: $(cat "$tmp/keep.txt")"
  sleep 0.05
done
line=$(grep "until Ctrl-C" "$tmp/keep.txt")
[[ $line =~ ^the\ search\ has\ ended:\ its\ dashboard\ page\ stays\ at\ (http://127\.0\.0\.1:[0-9]+)/\?token=[0-9a-f]{32}\ until\ Ctrl-C$ ]] ||
  fail "no serving line: $(cat "$tmp/keep.txt")"
base=${BASH_REMATCH[1]}
sleep 0.3
kill -0 "$pid" 2> /dev/null || fail "the page closed: $(cat "$tmp/keep.txt")"
state=$(curl -sf "$base/api/state") || fail "the kept page does not answer"
[[ $state == *'"phase":"ended"'* ]] || fail "the kept page does not show the end: $state"
kill -INT "$pid"
wait "$pid"
code=$?
pid=""
[[ $code -eq 0 || $code -eq 4 ]] || fail "Ctrl-C on a kept page: exit $code: $(cat "$tmp/keep.txt")"
echo "ok"
