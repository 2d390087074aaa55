#!/usr/bin/env bash
# The crowd scenes over many seeds, two runs at a time: one line per run
# with the scene, the seed, each team's arrivals and the collisions, then
# the runs in which a figure did not arrive or two touched.
# Usage: scripts/experiments/herd_seeds.sh build/bin/animrt . FIRST LAST [SCENE...]
set -euo pipefail
animrt=$1
root=$2
first=$3
last=$4
shift 4
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(counterflow gate crossing crossing_own_gaps maze corridor baffles)
runs=$(mktemp)
trap 'rm -f "$runs"' EXIT
for scene in "${scenes[@]}"; do
  for seed in $(seq "$first" "$last"); do echo "$scene $seed"; done
done |
  xargs -P 2 -L 1 sh -c '
    out=$("$0" herd "$1/configs/herd/$2.yaml" --quiet --seed "$3")
    teams=$(echo "$out" | grep -o "arrived [0-9]*/[0-9]*" | sed "s/arrived //" | tr "\n" " ")
    touching=$(echo "$out" | grep "^herd:" | grep -o "[0-9]* collisions" | head -1)
    echo "$2 $3 $teams$touching"' "$animrt" "$root" |
  sort -k1,1 -k2,2n >"$runs"
cat "$runs"
echo "-- runs in which a figure did not arrive or two touched:"
awk '{bad = $0 !~ / 0 collisions$/
      for (i = 3; i <= NF; ++i) if ($i ~ /\//) { split($i, a, "/"); if (a[1] != a[2]) bad = 1 }
      if (bad) print}' "$runs"
