#!/usr/bin/env bash
# animrt validate: the shipped robot passes; a broken one fails with exit 2 and
# one message naming file, line, column and key.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$animrt" validate "$root/configs/robots/quadruped.yaml" 2>&1) || fail "shipped config rejected: $out"
[[ $out == *": ok (12 joints, 1 bus, 12 devices"* ]] || fail "unexpected output: $out"

sed 's/^  rate_hz: .*/  rate_hz: fast/' "$root/configs/robots/quadruped.yaml" > "$tmp/bad.yaml"
sed -i "s#file: \.\./gaits/walk.yaml#file: $root/configs/gaits/walk.yaml#" "$tmp/bad.yaml"
out=$("$animrt" validate "$tmp/bad.yaml" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "exit code $code, expected 2: $out"
line=$(grep -n '^  rate_hz:' "$tmp/bad.yaml" | cut -d: -f1)
[[ $out == "error: $tmp/bad.yaml:$line:"*": loop.rate_hz: "*"fast"* ]] || fail "unexpected message: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

out=$("$animrt" validate "$tmp/missing.yaml" 2>&1)
[[ $? -eq 2 && $out == *"missing.yaml"*"cannot open"* ]] || fail "missing file: $out"
echo "validate: ok"
