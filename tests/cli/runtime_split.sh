#!/usr/bin/env bash
# animrt, what a figure runs, loads no learner: no MPI, no libtorch, no
# Recast. The offline tools' commands are still animrt's from the user's
# view (animrt-tools answers them); without animrt-tools, each of them,
# and `run --herd`, ends with one line naming the package to install,
# while the runtime's own commands work.
set -uo pipefail
animrt=$(realpath "$1")
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

libs=$(ldd "$animrt") || fail "ldd $animrt"
for lib in libmpi libopen-rte libtorch libc10 libRecast libDetour; do
  [[ $libs != *"$lib"* ]] && continue
  fail "animrt loads $lib: $(grep "$lib" <<<"$libs")"
done

out=$("$animrt" --help 2>&1) || fail "--help: $out"
for cmd in evolve gait head herd seq serve doctor; do
  [[ $out == *" $cmd "* ]] || fail "--help lists no $cmd: $out"
done
out=$("$animrt" herd --help 2>&1) || fail "herd --help through animrt-tools: $out"
[[ $out == *"Usage: "*"herd"* ]] || fail "herd --help: $out"

# animrt alone, as the runtime package installs it.
cp "$animrt" "$tmp/animrt"
out=$("$tmp/animrt" validate "$root/configs/robots/quadruped.yaml" 2>&1) ||
  fail "validate without the tools: $out"
for args in "evolve $root/configs/evolve/x.yaml" "seq corpus --help" \
  "run $root/configs/robots/quadruped.yaml --herd $root/configs/herd/x.yaml --agent a.0"; do
  out=$("$tmp/animrt" $args 2>&1)
  code=$?
  [[ $code == 1 ]] || fail "animrt $args without the tools: exit $code: $out"
  [[ $(wc -l <<<"$out") == 1 && $out == *"install the animrt-tools package"* ]] ||
    fail "animrt $args without the tools: $out"
  # It names the command that needs the tools: `run --herd`, not `run`.
  name=${args%% *}
  [[ $args == *--herd* ]] && name="run --herd"
  [[ $out == "error: \`animrt $name\` is one of the offline tools"* ]] ||
    fail "animrt $args without the tools names another command: $out"
done
echo "ok"
