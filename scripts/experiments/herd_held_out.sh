#!/usr/bin/env bash
# The counterflow scene changed in ways no herd parameter was tuned for,
# over many seeds: teams of 25 instead of 12, a gap of 4 m and of 1 m
# instead of 2 m, and the 2 m gap 3 m long (a corridor through a thick
# wall). The scenes are written from configs/herd/counterflow.yaml into a
# scratch folder; herd_seeds.sh runs them and lists the runs in which a
# figure did not arrive or two touched.
# Usage: scripts/experiments/herd_held_out.sh build/bin/animrt . FIRST LAST
set -euo pipefail
animrt=$(realpath "$1")
root=$(realpath "$2")
first=$3
last=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/configs/herd"
ln -s "$root/configs/gaits" "$work/configs/gaits"
ln -s "$root/configs/models" "$work/configs/models"
base=$root/configs/herd/counterflow.yaml
for part in 'center_m: \[0, -4\], size_m: \[0.5, 6\]' 'center_m: \[0, 4\], size_m: \[0.5, 6\]' \
  'count: 12'; do
  [ "$(grep -c "$part" "$base")" -ge 1 ] || {
    echo "herd_held_out: $base no longer has '$part', which this script rewrites" >&2
    exit 1
  }
done
walls() {  # both wall parts: distance of their centres from the gap's, length, thickness
  sed "s/center_m: \[0, -4\], size_m: \[0.5, 6\]/center_m: [0, -$1], size_m: [$3, $2]/;
       s/center_m: \[0, 4\], size_m: \[0.5, 6\]/center_m: [0, $1], size_m: [$3, $2]/" "$base"
}
sed 's/count: 12/count: 25/' "$base" >"$work/configs/herd/counterflow_teams25.yaml"
walls 4.5 5 0.5 >"$work/configs/herd/counterflow_gap4m.yaml"
walls 3.75 6.5 0.5 >"$work/configs/herd/counterflow_gap1m.yaml"
walls 4 6 3 >"$work/configs/herd/counterflow_corridor3m.yaml"
for f in "$work"/configs/herd/*.yaml; do
  ! cmp -s "$f" "$base" || { echo "herd_held_out: $f came out as $base" >&2; exit 1; }
done
"$root/scripts/experiments/herd_seeds.sh" "$animrt" "$work" "$first" "$last" \
  counterflow_teams25 counterflow_gap4m counterflow_gap1m counterflow_corridor3m
