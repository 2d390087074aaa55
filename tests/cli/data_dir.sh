#!/usr/bin/env bash
# Shipped data is found wherever animrt runs: `animrt seq corpus` with its
# default model, run from a folder that has no configs/, finds the model
# and gaits animrt ships (never the working directory's).
set -uo pipefail
animrt=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cd "$tmp" || fail "cannot enter $tmp"
out=$("$animrt" seq corpus --out "$tmp/corpus" --froude 0.06 --seeds 1 --frames 2 \
  --vertices 100 --quiet 2>&1) || fail "seq corpus from $tmp: $out"
[[ $out == "wrote 2 sequences "* ]] || fail "unexpected output: $out"
[[ -f $tmp/corpus/index.csv || -n $(ls "$tmp/corpus") ]] || fail "no corpus written"
echo "ok"
