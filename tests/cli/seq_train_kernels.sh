#!/usr/bin/env bash
# animrt seq train says which libtorch thread count and BLAS kernels it runs
# on, and on a CPU with AVX2 and FMA it does not train on OpenBLAS's generic
# SSE3 kernels ("Prescott", its fallback for a CPU model it does not know):
# animrt-seqnet restarts itself with better ones. A user's own
# OPENBLAS_CORETYPE is kept.
set -uo pipefail
animrt=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

source "$(dirname "$0")/seq_data.bash"
write_walk_csv "$tmp/walk.csv"

run() {
  "$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 1 "${small[@]}" 2>&1
}
out=$(env -u OPENBLAS_CORETYPE "$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" \
  --iterations 1 "${small[@]}" 2>&1) || fail "train failed: $out"
[[ $out =~ "libtorch threads 1, BLAS kernels "([A-Za-z0-9 ]+) ]] || fail "no kernels line: $out"
kernels=${BASH_REMATCH[1]}
if grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo; then
  [[ $kernels != Prescott ]] || fail "trains on the generic kernels on a CPU with AVX2: $out"
fi
if [[ $kernels != "not OpenBLAS" ]]; then
  out=$(OPENBLAS_CORETYPE=Prescott run) || fail "train failed: $out"
  [[ $out == *"BLAS kernels Prescott"* ]] || fail "the user's OPENBLAS_CORETYPE was not kept: $out"
fi
echo ok
