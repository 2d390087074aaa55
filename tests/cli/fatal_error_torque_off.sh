#!/usr/bin/env bash
# A fatal error inside animrt run switches torque off before the process
# ends, and the process still ends as the error would have ended it (the
# same signal in its status). Run on --backend hardware against
# `animrt sim`; an independent Protocol 2.0 client then reads Torque
# Enable = 0 on all 12 servos. Cases: an exception nobody catches in a
# helper thread (std::terminate), an assertion's SIGABRT, a SIGSEGV sent,
# and a real SIGSEGV: a helper thread's write to a page it may not write.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
fail() { echo "FAIL: $*"; exit 1; }
source "$root/tests/cli/figure_on_sim.bash"
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; [[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null;
      rm -rf "$tmp"' EXIT
ulimit -c 0  # no core files from the deaths below

start_sim

# expect_death WHAT CODE: the run died with CODE (128 + signal), said that
# it switched torque off, and every servo reads torque off.
expect_death() {
  wait $pid
  local code=$?
  pid=""
  [[ $code == "$2" ]] || fail "$1: exit $code, expected $2: $(cat "$tmp/out.txt" "$tmp/err.txt")"
  grep -q "^fatal: .*torque switched off on 1 of 1 bus before the process ends" "$tmp/err.txt" ||
    fail "$1: $(cat "$tmp/err.txt")"
  expect_torque_off "$1"
}

# The injected exception comes 1.2 s after the run starts: after the start
# ramp (0.5 s, once the servos are found), during the motion. Every run has
# a --duration, so one that does not die ends (and fails) by itself.
ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S=1.2 start_figure --duration 3
expect_death "uncaught exception" 134
grep -q "terminate called after throwing an instance of 'std::runtime_error'" "$tmp/err.txt" ||
  fail "uncaught exception: the exception is not named: $(cat "$tmp/err.txt")"

start_figure --duration 3
sleep 0.8
kill -ABRT $pid
expect_death "SIGABRT" 134

start_figure --duration 3
sleep 0.8
kill -SEGV $pid
expect_death "SIGSEGV" 139

# Under AddressSanitizer the real fault goes on to the sanitizer's own
# handler after torque is off, which reports it and exits 1.
# (ldd's output is read whole: under pipefail, grep -q stopping at the first
# match can fail the pipe with ldd's SIGPIPE.)
real_segv=139
[[ $(ldd "$animrt" 2>/dev/null) == *libasan* ]] && real_segv=1
ANIMRT_TEST_BAD_WRITE_AFTER_S=1.2 start_figure --duration 3
expect_death "a write to a page without access" $real_segv
echo "fatal_error_torque_off: ok"
