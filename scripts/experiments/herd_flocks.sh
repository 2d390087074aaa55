#!/usr/bin/env bash
# Flock metrics of every shipped flock scene over seeds 1-5: the line
# `animrt herd` prints per flock (order, mean speed against the leader's,
# centre to leader).
# Usage: scripts/experiments/herd_flocks.sh build/bin/animrt .
set -euo pipefail
animrt=$1
root=$2
for scene in flock unity pasture; do
  for seed in 1 2 3 4 5; do
    echo "== $scene seed $seed"
    "$animrt" herd "$root/configs/herd/$scene.yaml" --quiet --seed "$seed" |
      grep -E "^herd:|reynolds|unity"
  done
done
