#!/usr/bin/env bash
# animrt run --dashboard: a non-loopback address without --dashboard-remote
# is a usage error; otherwise the one startup line comes first on stdout and
# its URL's token stops the run through the ramp (and nothing else does).
# animrt herd --dashboard: the same rules, a herd's info, and a stop with
# the token ends the herd (at real time it would run on for 30 s).
# animrt evolve --dashboard: the same rules and line; the curves fill, a stop
# without the token changes nothing, one with it ends the search after its
# generation with the results written as at a normal end, also under MPI
# (every rank stops, at the same generation).
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
robot=$root/configs/robots/quadruped.yaml

"$animrt" run "$robot" --lockstep --duration 1 --dashboard 0.0.0.0:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "a non-loopback dashboard without --dashboard-remote was not a usage error"
grep -q "dashboard-remote" "$tmp/e" || fail "the message does not name --dashboard-remote: $(cat "$tmp/e")"
"$animrt" run "$robot" --lockstep --duration 1 --dashboard 127.0.0.1 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "--dashboard without a port was not a usage error"

"$animrt" run "$robot" --lockstep --no-realtime --dashboard 127.0.0.1:0 \
  > "$tmp/out.txt" 2> "$tmp/err.txt" &
pid=$!
for _ in $(seq 1 200); do
  [[ -s $tmp/out.txt ]] && break
  sleep 0.05
done
line=$(head -n 1 "$tmp/out.txt")
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "first line is not the dashboard's: '$line'"
base=${BASH_REMATCH[1]}
token=${BASH_REMATCH[2]}
/usr/bin/python3 - "$base" "$token" <<'PY' || fail "the dashboard did not answer as it should"
import json, sys, time, urllib.request, urllib.error
base, token = sys.argv[1], sys.argv[2]
info = json.load(urllib.request.urlopen(base + "/api/info"))
assert info["robot"] == "quadruped" and len(info["joints"]) == 12, info
assert info["model"] is not None and info["model"]["bodies"][0]["name"] == "torso"
def post(path, token):
    req = urllib.request.Request(base + path, data=b"{}", method="POST")
    if token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
assert post("/api/stop", None) == 401
assert post("/api/stop", "0" * 32) == 401
time.sleep(0.3)
assert json.load(urllib.request.urlopen(base + "/api/state"))["phase"] != "ended"
assert post("/api/stop", token) == 200
PY
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "the stopped run exited $rc: $(cat "$tmp/err.txt")"
grep -q "ended by stop request" "$tmp/out.txt" || fail "summary: $(cat "$tmp/out.txt")"
[[ $(grep -c "^dashboard:" "$tmp/out.txt") -eq 1 ]] || fail "more than one dashboard line"
herd=$root/configs/herd/gate.yaml
"$animrt" herd "$herd" --quiet --duration 1 --dashboard 0.0.0.0:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "herd: a non-loopback dashboard without --dashboard-remote was not a usage error"
"$animrt" herd "$herd" --quiet --duration 30 --dashboard 127.0.0.1:0 > "$tmp/herd.txt" 2>&1 &
pid=$!
for _ in $(seq 1 200); do
  [[ -s $tmp/herd.txt ]] && break
  sleep 0.05
done
line=$(head -n 1 "$tmp/herd.txt")
[[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
  fail "herd: first line is not the dashboard's: '$line'"
/usr/bin/python3 - "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" <<'PY' || fail "the herd's dashboard did not answer as it should"
import json, sys, urllib.request, urllib.error
base, token = sys.argv[1], sys.argv[2]
info = json.load(urllib.request.urlopen(base + "/api/info"))
assert info["kind"] == "herd" and info["agents"] == 8, info
assert len(json.load(urllib.request.urlopen(base + "/api/state"))["agents"]) == 8
def post(path, token):
    req = urllib.request.Request(base + path, data=b"{}", method="POST")
    if token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
assert post("/api/stop", None) == 401
assert post("/api/stop", token) == 200
PY
wait $pid
rc=$?
pid=""
[[ $rc -eq 0 ]] || fail "the stopped herd exited $rc: $(cat "$tmp/herd.txt")"
grep -q "stopped from the dashboard" "$tmp/herd.txt" || fail "herd summary: $(cat "$tmp/herd.txt")"

cat > "$tmp/evolve.yaml" <<EOF
name: dashboard_cli
grammar: $root/configs/grammars/quadruped_sinusoidal.bnf
model: $root/configs/models/quadruped.xml
seed_gait: $root/configs/gaits/quadruped_seed.yaml
search: {seed: 3, population: 10, generations: 1000, elites: 2, max_depth: 6}
walk: {settle_s: 0.1, warmup_cycles: 1, measure_cycles: 1}
EOF
"$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/g.yaml" --dashboard 0.0.0.0:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "evolve: a non-loopback dashboard without --dashboard-remote was not a usage error"
grep -q "dashboard-remote" "$tmp/e" || fail "evolve: the message does not name --dashboard-remote: $(cat "$tmp/e")"
# The Pareto search has no dashboard: asking for both is a usage error.
"$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/front" --pareto --dashboard 127.0.0.1:0 > "$tmp/o" 2> "$tmp/e"
[[ $? -eq 1 ]] || fail "evolve --pareto --dashboard was not a usage error"
grep -q -- "--pareto" "$tmp/e" || fail "the message does not name --pareto: $(cat "$tmp/e")"
[[ ! -e "$tmp/front" ]] || fail "evolve --pareto --dashboard wrote results"
[[ ! -e $tmp/g.yaml ]] || fail "evolve: a usage error wrote a gait"
# The search's stop under MPI: rank 0 serves the page, every rank must stop.
command -v mpirun > /dev/null 2>&1 || fail "mpirun not found (scripts/install-deps.sh installs Open MPI)"
mpirun=(env OMPI_MCA_plm_rsh_agent=false ASAN_OPTIONS=detect_leaks=0 mpirun --allow-run-as-root
        --oversubscribe -np 2)
for mode in threads mpi; do
  if [[ $mode == mpi ]]; then
    launch=("${mpirun[@]}" "$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/$mode.yaml" --threads 1 --mpi)
  else
    launch=("$animrt" evolve "$tmp/evolve.yaml" --out "$tmp/$mode.yaml" --threads 1)
  fi
  "${launch[@]}" --dashboard 127.0.0.1:0 > "$tmp/$mode.txt" 2>&1 &
  pid=$!
  for _ in $(seq 1 400); do
    [[ -s $tmp/$mode.txt ]] && break
    sleep 0.05
  done
  line=$(head -n 1 "$tmp/$mode.txt")
  [[ $line =~ ^dashboard:\ (http://127\.0\.0\.1:[0-9]+)/\?token=([0-9a-f]{32})$ ]] ||
    fail "evolve ($mode): first line is not the dashboard's: '$line'"
  /usr/bin/python3 - "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" <<'PY' || fail "evolve ($mode): the dashboard did not answer as it should"
import json, sys, time, urllib.request, urllib.error
base, token = sys.argv[1], sys.argv[2]
info = json.load(urllib.request.urlopen(base + "/api/info"))
assert info["kind"] == "evolve" and info["generations"] == 1000 and len(info["joints"]) == 12, info
assert info["model"]["bodies"][0]["name"] == "torso", info["model"]
def state():
    return json.load(urllib.request.urlopen(base + "/api/state"))
def post(path, token):
    req = urllib.request.Request(base + path, data=b"{}", method="POST")
    if token:
        req.add_header("Authorization", "Bearer " + token)
    try:
        return urllib.request.urlopen(req).status
    except urllib.error.HTTPError as e:
        return e.code
deadline = time.monotonic() + 30
while len(state()["history"]) < 2:
    assert time.monotonic() < deadline, "no two generations in 30 s"
    time.sleep(0.05)
assert post("/api/stop", None) == 401
assert post("/api/stop", "0" * 32) == 401
s = state()
assert s["phase"] == "running", s["phase"]
assert [h["generation"] for h in s["history"]] == list(range(len(s["history"]))), s["history"]
assert s["bodies"]["measured"] and s["best"]["fitness"] > 0, s
assert post("/api/stop", token) == 200
PY
  wait $pid
  rc=$?
  pid=""
  [[ $rc -eq 0 ]] || fail "evolve ($mode): the stopped search exited $rc: $(cat "$tmp/$mode.txt")"
  last=$(sed -n 's/^stopped from the dashboard after generation \([0-9]*\) of 1000$/\1/p' "$tmp/$mode.txt")
  [[ -n $last ]] || fail "evolve ($mode): no stop line: $(cat "$tmp/$mode.txt")"
  for f in "$mode.yaml" "$mode.csv" "$mode.svg"; do
    [[ -s $tmp/$f ]] || fail "evolve ($mode): $f not written after the stop"
  done
  # The CSV: a header and generations 0..last.
  [[ $(wc -l < "$tmp/$mode.csv") -eq $((last + 2)) ]] ||
    fail "evolve ($mode): the CSV has $(wc -l < "$tmp/$mode.csv") lines after a stop at generation $last"
  [[ $(grep -c "^dashboard:" "$tmp/$mode.txt") -eq 1 ]] || fail "evolve ($mode): more than one dashboard line"
done
echo ok

