#!/usr/bin/env bash
# animrt serve as systemd's Type=notify service sees it (a datagram socket
# stands in for systemd): READY=1 once the start ramp has ended (after the
# watchdog pings of the ramp's cycles), WATCHDOG=1 while the loop completes
# cycles, none once the loop stalls (a stuck loop, however alive the rest
# of the process), and STOPPING=1 when SIGTERM starts the stop ramp, which
# then ends the service with exit 0, the watchdog fed until the exit once
# the figure is released.
set -uo pipefail
animrt=$1
root=$(realpath "$2")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The shipped figure with half-second ramps, beside links to its files.
mkdir -p "$tmp/configs/robots"
for dir in shows modbus; do ln -s "$root/configs/$dir" "$tmp/configs/$dir"; done
sed 's/start_ramp_s: 2.0/start_ramp_s: 0.5/; s/stop_ramp_s: 2.0/stop_ramp_s: 0.5/' \
  "$root/configs/robots/animatronic.yaml" >"$tmp/configs/robots/animatronic.yaml"
serve=("$animrt" serve "$tmp/configs/robots/animatronic.yaml"
  --cues "$root/configs/cues/animatronic.yaml" --no-osc --no-artnet --no-realtime)
notify() { /usr/bin/python3 "$root/tests/cli/service_notify.py" "$@"; }
count() { awk -v m="$2" -v from="$3" -v to="$4" '$2 == m && $1 >= from && $1 < to' "$1" | wc -l; }
at() { awk -v m="$2" '$2 == m { print $1; exit }' "$1"; }

# The three services below run at the same time (each observed on a socket
# of its own): the test waits on their clocks, not on its machine.
# Ready, alive, stopped by SIGTERM one second after READY.
notify "$tmp/term.txt" 200000 30 --term-after-ready 1 -- "${serve[@]}" &
# A clean stop whose exit is slow (the summary written on a loaded machine):
# the figure is released, and the watchdog is fed until the process exits.
ANIMRT_TEST_SLOW_EXIT_S=1.5 notify "$tmp/slow.txt" 200000 30 --term-after-ready 0.3 -- "${serve[@]}" &
# The loop stalls 2.5 s after the run began: the pings stop, the process lives on.
ANIMRT_TEST_STALL_LOOP_AFTER_S=2.5 notify "$tmp/stall.txt" 200000 6 -- "${serve[@]}" &
wait

log=$(cat "$tmp/term.txt")
ready=$(at "$tmp/term.txt" READY=1)
[[ -n $ready ]] || fail "no READY=1: $log"
[[ $(count "$tmp/term.txt" WATCHDOG=1 0 "$ready") -ge 3 ]] ||
  fail "READY=1 came before the start ramp's cycles: $log"
[[ $(count "$tmp/term.txt" WATCHDOG=1 "$ready" 1e9) -ge 3 ]] || fail "no watchdog pings: $log"
sent=$(at "$tmp/term.txt" sent)
stopping=$(at "$tmp/term.txt" STOPPING=1)
[[ -n $sent && -n $stopping ]] || fail "no STOPPING=1 after SIGTERM: $log"
grep -q " exit 0$" "$tmp/term.txt" || fail "SIGTERM did not end the service with exit 0: $log"
[[ $(grep -c "READY=1\|STOPPING=1" "$tmp/term.txt") == 2 ]] || fail "sent twice: $log"

# The slow exit.
log=$(cat "$tmp/slow.txt")
grep -q " exit 0$" "$tmp/slow.txt" || fail "slow exit: not ended with exit 0: $log"
exited=$(at "$tmp/slow.txt" exit)
last=$(awk '$2 == "WATCHDOG=1" { t = $1 } END { print t }' "$tmp/slow.txt")
awk -v t="$last" -v e="$exited" 'BEGIN { exit !(t != "" && e - t < 0.75) }' ||
  fail "slow exit: no watchdog ping in the last 0.75 s before the exit: $log"

# The stalled loop.
log=$(cat "$tmp/stall.txt")
ready=$(at "$tmp/stall.txt" READY=1)
[[ -n $ready ]] || fail "stall: no READY=1 before the stall (a loaded machine?): $log"
[[ $(count "$tmp/stall.txt" WATCHDOG=1 "$ready" 1e9) -ge 1 ]] || fail "stall: no pings at all: $log"
grep -q " killed$" "$tmp/stall.txt" || fail "stall: the process ended: $log"
last=$(awk '$2 == "WATCHDOG=1" { t = $1 } END { print t }' "$tmp/stall.txt")
awk -v t="$last" 'BEGIN { exit !(t < 5.0) }' || fail "stall: pings went on after the loop stalled: $log"
echo "ok"
