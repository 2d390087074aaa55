# Sourced by the CLI tests of `animrt serve` on a simulated figure. Needs
# $animrt and $root from the sourcing script; sets $tmp (removed on exit)
# and fail(), and kills a serve still running when the script exits.
#
#   serve_in_background ARGS...  starts `animrt serve ARGS`, its output in
#                                $tmp/out.txt and $tmp/err.txt; sets $pid
#   await_line PATTERN FILE      waits up to 15 s for a line matching PATTERN
#   start_serve ARGS...          serve_in_background, then returns once torque
#                                is on; sets $line (the first line of output)
#   wait_exit                    waits up to 30 s for the serve to end, then
#                                reaps it (poll_exit, reap); sets $code
#   bad_cues TEXT LINE KEY       serves the animatronic with the cue file TEXT
#                                and expects it refused: exit 2, one error
#                                naming the file, LINE (a grep pattern) and
#                                KEY, and no device started

tmp=$(mktemp -d)
pid=""
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

serve_in_background() {
  # Emptied first: the new process may not have truncated them yet when
  # await_line first looks, and an earlier serve's lines are in them.
  : > "$tmp/out.txt"
  : > "$tmp/err.txt"
  "$animrt" serve "$@" > "$tmp/out.txt" 2> "$tmp/err.txt" &
  pid=$!
}

await_line() {
  for _ in $(seq 150); do
    grep -q "$1" "$2" && break
    sleep 0.1
  done
}

start_serve() {
  serve_in_background "$@"
  await_line "activate: torque on" "$tmp/err.txt"
  grep -q "activate: torque on" "$tmp/err.txt" ||
    fail "serve did not start: $(cat "$tmp/out.txt" "$tmp/err.txt")"
  line=$(head -n 1 "$tmp/out.txt")
}

poll_exit() {
  for _ in $(seq 300); do
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
  done
}

reap() {
  wait $pid
  code=$?
  pid=""
}

wait_exit() {
  poll_exit
  reap
}

bad_cues() {
  printf '%s\n' "$1" > "$tmp/bad.yaml"
  "$animrt" serve "$root/configs/robots/animatronic.yaml" --cues "$tmp/bad.yaml" --lockstep \
    > "$tmp/out.txt" 2> "$tmp/err.txt"
  code=$?
  [[ $code == 2 ]] || fail "bad cue file: exit $code, expected 2: $(cat "$tmp/err.txt")"
  grep -q "^error: $tmp/bad.yaml:$2:.*$3" "$tmp/err.txt" || fail "bad cue file: $(cat "$tmp/err.txt")"
  grep -q "configure" "$tmp/err.txt" && fail "a device started for a bad cue file: $(cat "$tmp/err.txt")"
}
