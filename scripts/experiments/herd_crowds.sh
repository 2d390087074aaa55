#!/usr/bin/env bash
# The crowd scenes over seeds 1-5: per seed, the herd's line (collisions,
# contact stops) and each team's (arrived, worst time to goal against the
# straight-line time).
# Usage: scripts/experiments/herd_crowds.sh build/bin/animrt . [SCENE...]
set -euo pipefail
animrt=$1
root=$2
shift 2
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(counterflow gate crossing crossing_own_gaps maze corridor baffles)
for scene in "${scenes[@]}"; do
  for seed in 1 2 3 4 5; do
    echo "== $scene seed $seed"
    "$animrt" herd "$root/configs/herd/$scene.yaml" --quiet --seed "$seed" |
      grep -E "^herd:|crowd" |
      sed -E 's/order [^,]*, speed [^,]*, nearest neighbour [^,]*, //; s/, path .*(, stuck)/\1/'
  done
done
