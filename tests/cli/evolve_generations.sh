#!/usr/bin/env bash
# animrt evolve --generations G runs G generations, the initial one
# included: the CSV has a header and G rows, the last progress line is
# generation G-1. --generations 0 is a usage error (exit 1).
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat > "$tmp/evolve.yaml" <<EOF
name: count
grammar: $root/configs/grammars/quadruped_sinusoidal.bnf
model: $root/configs/models/quadruped.xml
seed_gait: $root/configs/gaits/quadruped_seed.yaml
search: {seed: 3, population: 2, generations: 50, elites: 1, max_depth: 6}
walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}
EOF
out=$("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/g.yaml" --threads 1 --generations 3 2>&1)
code=$?
[[ $code -eq 0 || $code -eq 4 ]] || fail "evolve exited $code: $out"
[[ $(wc -l < "$tmp/g.csv") -eq 4 ]] || fail "--generations 3: $(($(wc -l < "$tmp/g.csv") - 1)) generations in the CSV"
[[ $out == *", 3 generations, seed 3"* ]] || fail "the start line does not say 3 generations: $out"
[[ $(echo "$out" | grep -c '^gen ') -eq 3 ]] || fail "not 3 progress lines: $out"

"$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/none.yaml" --generations 0 > "$tmp/o" 2>&1
code=$?
[[ $code -eq 1 ]] || fail "--generations 0: exit $code, expected 1: $(cat "$tmp/o")"
[[ ! -e $tmp/none.yaml ]] || fail "--generations 0 wrote a gait"
echo "ok"
