#!/usr/bin/env bash
# Time from a signal to torque off, read back from the simulated servos by an
# independent client: `animrt run --backend hardware` of the quadruped (its
# shipped ramps, timeouts widened as in the CLI tests) against `animrt sim`,
# signalled 1.5 s into the motion. Prints, per signal and try, the time to
# the process's exit and to a Torque Enable read back as 0 on all 12 servos.
#
# usage: bench/signal_to_torque_off.sh ANIMRT ROOT [TRIES] [SIGNAL...]
set -uo pipefail
animrt=$1
root=$2
tries=${3:-3}
shift 3 2> /dev/null || shift $#
signals=("${@:-TERM HUP SEGV}")
read -r -a signals <<< "${signals[*]}"
tmp=$(mktemp -d)
fail() { echo "FAIL: $*"; exit 1; }
source "$root/tests/cli/figure_on_sim.bash"
trap '[[ -n $pid ]] && kill -KILL $pid 2>/dev/null; [[ -n $sim_pid ]] && kill $sim_pid 2>/dev/null;
      rm -rf "$tmp"' EXIT
ulimit -c 0
start_sim
# The shipped ramps (figure_on_sim.bash shortens them for the tests).
sed -E -i -e "s|^(\s*start_ramp_s:\s*)[0-9.]+|\12.0|" -e "s|^(\s*stop_ramp_s:\s*)[0-9.]+|\12.0|" "$robot"
now() { date +%s.%N; }
for sig in "${signals[@]}"; do
  for _ in $(seq "$tries"); do
    start_figure
    sleep 3.5  # start ramp 2 s, then 1.5 s of motion
    t0=$(now)
    kill -"$sig" $pid
    wait $pid
    code=$?
    t1=$(now)
    pid=""
    expect_torque_off "SIG$sig"
    t2=$(now)
    awk -v s="$sig" -v c="$code" -v a="$t0" -v b="$t1" -v d="$t2" \
      'BEGIN { printf "SIG%-5s exit %3d  signal -> exit %6.3f s  signal -> torque off read back %6.3f s\n", s, c, b - a, d - a }'
  done
done
