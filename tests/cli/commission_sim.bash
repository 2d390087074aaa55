# Shared by the commissioning tests: a copy of a shipped robot in a temp
# folder (its gait and model folders linked beside it, so its relative paths
# resolve), its simulated devices served with the control interface, and a
# client for that interface. Sourced; needs $animrt, $root, $tmp and fail().

# copy_robot NAME: $tmp/robots/NAME.yaml
copy_robot() {
  mkdir -p "$tmp/robots"
  cp "$root/configs/robots/$1.yaml" "$tmp/robots/$1.yaml"
  ln -sfn "$root/configs/gaits" "$tmp/gaits"
  ln -sfn "$root/configs/models" "$tmp/models"
}

# launch_sim ROBOT: starts serving its devices (sets sim_pid), without
# waiting for them. A script's background job starts with SIGINT ignored, so
# a SIGINT sent before animrt has its handlers (stop_sim after a failed
# start) would be lost and the wait for the simulator never end: it starts
# with SIGINT at its default, which ends it until its handler takes over.
launch_sim() {
  : > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
  (
    trap - INT QUIT
    exec "$animrt" sim "$1" --control "$tmp/ctl"
  ) > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
}

# start_sim ROBOT: serves its devices; sets sim_pid and pty (the first serial bus).
start_sim() {
  launch_sim "$1"
  for _ in $(seq 100); do
    grep -q "^control " "$tmp/sim.txt" && break
    sleep 0.1
  done
  [[ -S $tmp/ctl ]] || fail "no control socket: $(cat "$tmp/sim.txt")"
  read -r _ _ pty < <(grep "^serial " "$tmp/sim.txt")
}

# stop_sim: SIGINT, as Ctrl-C, once the process is animrt (the shell's
# child before its exec would take a SIGINT by running this script's EXIT
# trap); a simulator that has not ended 10 s later is killed and the test
# fails.
stop_sim() {
  [[ -n ${sim_pid:-} ]] || return 0
  local pid=$sim_pid exe
  sim_pid=""
  exe=$(readlink -f "$animrt")
  for _ in $(seq 1000); do
    [[ $(readlink "/proc/$pid/exe" 2>/dev/null) == "$exe" ]] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.01
  done
  kill -INT "$pid" 2>/dev/null || return 0
  for _ in $(seq 200); do
    kill -0 "$pid" 2>/dev/null || { wait "$pid" 2>/dev/null; return 0; }
    sleep 0.05
  done
  kill -KILL "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  fail "animrt sim did not end within 10 s of SIGINT: $(cat "$tmp/sim.txt")"
}

ctl() {
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "$1"
}
