#!/usr/bin/env bash
# animrt herd's summary reports only what it measured: a Unity flock that
# stands while its leader walks is reported as standing with
# no order (text and JSON, with both speeds); a one-figure crowd that cannot
# reach its goal in time has no pair distance, neighbour or time to goal;
# a summary or top view that cannot be written is refused before it steps.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# A flock whose boids feel no pull (every force 0) stands while its
# leader walks: the leader's move carries the boids, but at 0.04 m/s,
# under half the pony's slowest walk (0.086 m/s), so the figures stand.
cat > "$tmp/standing.yaml" <<YAML
bounds_m: [-20, -20, 20, 20]
duration_s: 100
figures:
  pony: {gait: $root/configs/gaits/pony.yaml, radius_m: 0.25}
groups:
  - name: flock
    kind: unity
    figure: pony
    count: 30
    spawn_m: [-6, -6, 6, 6]
    leader: {wander_m: [-12, -12, 12, 12], speed_mps: 0.04, reach_m: 1.0, max_turn_dps: 6}
    params: {min_speed: 0.0, random_force: 0.0, to_origin_force: 0.0, gravity: 0.0,
             avoidance_force: 0.0, follow_velocity: 0.0}
YAML
out=$("$animrt" herd "$tmp/standing.yaml" --summary-json "$tmp/u.json" --quiet 2>&1) ||
  fail "herd failed: $out"
[[ $out == *"flock (unity, 30 figures): 0 collisions, standing, speed "*"(leader 0.0400 m/s)"* ]] ||
  fail "unity summary: $out"
[[ $out != *"order"* ]] || fail "a standing flock printed an order: $out"
/usr/bin/python3 - "$tmp/u.json" <<'PY' || fail "unity JSON: $(cat "$tmp/u.json")"
import json, sys
assert json.load(open(sys.argv[1]))["knots"] == 0
g = json.load(open(sys.argv[1]))["groups"][0]
assert g["standing"] is True and g["order_mean"] is None and g["order_min"] is None
assert g["speed_mean_mps"] < 0.1 * g["leader_speed_mean_mps"]
assert abs(g["leader_speed_mean_mps"] - 0.04) < 0.005
PY

cat > "$tmp/one.yaml" <<YAML
bounds_m: [-5, -5, 5, 5]
duration_s: 10
figures:
  pony: {gait: $root/configs/gaits/herd_pony.yaml, radius_m: 0.25}
groups:
  - {name: solo, kind: crowd, figure: pony, count: 1, spawn_m: [-4, -1, -3, 1],
     target_m: [4, 0], speed_mps: [0.1, 0.1]}
YAML
out=$("$animrt" herd "$tmp/one.yaml" --summary-json "$tmp/one.json" --quiet 2>&1) ||
  fail "one-figure herd failed: $out"
[[ $out == *"min pair distance n/a"* && $out == *"order n/a"* && $out == *"nearest neighbour n/a"* &&
  $out == *"arrived 0/1, time to goal n/a, path n/a, stuck 0"* ]] || fail "one-figure summary: $out"
/usr/bin/python3 - "$tmp/one.json" <<'PY' || fail "one-figure JSON: $(cat "$tmp/one.json")"
import json, sys
j = json.load(open(sys.argv[1]))
g = j["groups"][0]
assert j["min_pair_distance_m"] is None and j["min_clearance_m"] is None
assert g["order_mean"] is None and g["nearest_neighbour_mean_m"] is None
assert g["arrivals"] == 0 and g["time_to_goal_mean_s"] is None and g["stuck"] == 0
PY
# The summary and the top view are written at the end, but a path that
# cannot be written is refused before the herd takes a step, not after it.
for opt in --summary-json --svg --out; do
  out=$("$animrt" herd "$tmp/one.yaml" "$opt" "$tmp/missing/x" --quiet 2>&1) &&
    fail "herd $opt in a missing folder succeeded: $out"
  [[ $(echo "$out" | head -1) == "$opt: $tmp/missing/x: its folder \"$tmp/missing\" does not exist" ]] ||
    fail "herd $opt in a missing folder: $out"
  out=$("$animrt" herd "$tmp/one.yaml" "$opt" "$tmp" --quiet 2>&1) && fail "herd $opt $tmp succeeded"
  [[ $(echo "$out" | head -1) == "$opt: $tmp: is a folder, expected a file to write" ]] ||
    fail "herd $opt $tmp: $out"
  [[ $out != *"min pair distance"* ]] || fail "herd $opt stepped the herd first: $out"
done
# One written when the run is over that fails (a full disk) names its
# option, its path and why, as every command's output files do.
for opt in --summary-json --svg --out; do
  out=$("$animrt" herd "$tmp/one.yaml" "$opt" /dev/full --quiet 2>&1) &&
    fail "herd $opt /dev/full succeeded: $out"
  [[ $out == *"$opt: cannot write /dev/full: No space left on device"* ]] ||
    fail "herd $opt /dev/full: $out"
done
# A scene whose figure cannot be loaded (its gait's calibration table holds
# no points) leaves the last run's summary and top view as they were.
mkdir "$tmp/gait"
cp "$root/configs/gaits/herd_pony.yaml" "$tmp/gait/"
printf 'gait: herd_pony.yaml\nmodel: %s\ntolerance: 0.15\npoints: []\n' \
  "$root/configs/models/pony.xml" > "$tmp/gait/herd_pony.calibration.yaml"
sed "s#$root/configs/gaits/herd_pony.yaml#$tmp/gait/herd_pony.yaml#" "$tmp/one.yaml" > "$tmp/bad_gait.yaml"
echo "last run" > "$tmp/keep.json"
echo "last run" > "$tmp/keep.svg"
out=$("$animrt" herd "$tmp/bad_gait.yaml" --summary-json "$tmp/keep.json" --svg "$tmp/keep.svg" --quiet 2>&1) &&
  fail "a figure without a calibrated walk was loaded: $out"
[[ $out == *"points: expected a list of points, found []"* ]] || fail "bad calibration: $out"
[[ $(cat "$tmp/keep.json") == "last run" && $(cat "$tmp/keep.svg") == "last run" ]] ||
  fail "the last run's files were emptied by a run that never started"
# A run that fails after its end files were opened (the dashboard's port
# is taken) leaves no empty new file where there was none.
/usr/bin/python3 -c '
import socket, sys, time
s = socket.socket(); s.bind(("127.0.0.1", 0)); s.listen()
print(s.getsockname()[1], flush=True); time.sleep(30)' > "$tmp/port.txt" &
holder=$!
for _ in $(seq 50); do [[ -s $tmp/port.txt ]] && break; sleep 0.1; done
port=$(cat "$tmp/port.txt")
[[ -n $port ]] || { kill "$holder"; fail "no port to hold"; }
out=$("$animrt" herd "$tmp/one.yaml" --summary-json "$tmp/new.json" --svg "$tmp/new.svg" \
  --dashboard "127.0.0.1:$port" --quiet 2>&1)
code=$?
kill "$holder" 2>/dev/null
[[ $code -ne 0 && $out == *"cannot listen on 127.0.0.1:$port"* ]] ||
  fail "a dashboard on a taken port: exit $code: $out"
[[ ! -e $tmp/new.json && ! -e $tmp/new.svg ]] ||
  fail "a run that failed left new files: $(ls "$tmp"); $out"
echo "herd_summary: ok"
