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

# start_sim ROBOT: serves its devices; sets sim_pid and pty (the first serial bus).
start_sim() {
  : > "$tmp/sim.txt"  # emptied first: the last sim's lines are not this one's
  "$animrt" sim "$1" --control "$tmp/ctl" > "$tmp/sim.txt" 2>&1 &
  sim_pid=$!
  for _ in $(seq 100); do
    grep -q "^control " "$tmp/sim.txt" && break
    sleep 0.1
  done
  [[ -S $tmp/ctl ]] || fail "no control socket: $(cat "$tmp/sim.txt")"
  read -r _ _ pty < <(grep "^serial " "$tmp/sim.txt")
}

stop_sim() {
  [[ -n ${sim_pid:-} ]] && kill -INT "$sim_pid" 2>/dev/null && wait "$sim_pid" 2>/dev/null
  sim_pid=""
}

ctl() {
  /usr/bin/python3 -c 'import socket,sys; s=socket.socket(socket.AF_UNIX); s.connect(sys.argv[1]); s.sendall((sys.argv[2]+"\n").encode()); print(s.makefile().readline(), end="")' "$tmp/ctl" "$1"
}
