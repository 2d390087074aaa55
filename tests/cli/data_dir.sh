#!/usr/bin/env bash
# Shipped data is found wherever animrt runs, never in the working
# directory: `animrt seq corpus` with its default model, run from a folder
# that has no configs/, finds the model and gaits animrt ships; an animrt
# installed under a prefix finds them (and the dashboard's page) in
# PREFIX/share/animrt.
set -uo pipefail
animrt=$(realpath "$1")
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

corpus() {
  "$1" seq corpus --out "$2" --froude 0.06 --seeds 1 --frames 2 --vertices 100 --quiet 2>&1
}
cd "$tmp" || fail "cannot enter $tmp"
out=$(corpus "$animrt" "$tmp/corpus") || fail "seq corpus from $tmp: $out"
[[ $out == "wrote 2 sequences "* ]] || fail "unexpected output: $out"

# Installed: PREFIX/bin/animrt (and animrt-tools, which answers seq) and
# the data in PREFIX/share/animrt.
mkdir -p "$tmp/prefix/bin" "$tmp/prefix/share" "$tmp/elsewhere"
cp "$animrt" "$tmp/prefix/bin/animrt"
cp "$(dirname "$animrt")/animrt-tools" "$tmp/prefix/bin/animrt-tools"
ln -s "$root/configs" "$tmp/prefix/share/animrt"
cd "$tmp/elsewhere" || fail "cannot enter $tmp/elsewhere"
out=$(corpus "$tmp/prefix/bin/animrt" "$tmp/installed") || fail "installed seq corpus: $out"
[[ $out == "wrote 2 sequences "* ]] || fail "unexpected output (installed): $out"
out=$("$tmp/prefix/bin/animrt" seq corpus --help 2>&1)
[[ $out == *"--configs TEXT=$tmp/prefix/share/animrt"$'\n'* ]] || fail "installed data folder: $out"
out=$("$tmp/prefix/bin/animrt" view --help 2>&1)
[[ $out == *"--dashboard-www TEXT:DIR=$tmp/prefix/share/animrt/www"* ]] ||
  fail "installed dashboard page: $out"
echo "ok"
