#!/usr/bin/env bash
# animrt --version names the release; every --help shows the options'
# defaults; `animrt seq train --help` names the command the user typed.
set -uo pipefail
animrt=$1
fail() { echo "FAIL: $*"; exit 1; }

version=$(sed -n 's/^project(animrt VERSION \([0-9.]*\).*/\1/p' "$2/CMakeLists.txt")
out=$("$animrt" --version 2>&1) || fail "--version failed: $out"
[[ $out == "animrt $version" ]] || fail "--version: $out (expected animrt $version)"

out=$("$animrt" run --help 2>&1) || fail "run --help failed: $out"
[[ $out == *"--dashboard-rate "*"=30"* ]] || fail "run --help shows no default stream rate: $out"
out=$("$animrt" view --help 2>&1) || fail "view --help failed: $out"
[[ $out == *"--dashboard TEXT=127.0.0.1:0"* ]] || fail "view --help shows no default address: $out"
out=$("$animrt" herd --help 2>&1) || fail "herd --help failed: $out"
[[ $out == *"--dashboard-speed "*"=1"* ]] || fail "herd --help shows no default pace: $out"

out=$("$animrt" seq corpus --help 2>&1) || fail "seq corpus --help failed: $out"
[[ $out == *"--vertices "*"=1000"* ]] || fail "seq corpus --help shows no default vertices: $out"
[[ $out != *"=[]"* ]] || fail "an empty list shown as a default: $out"
# A required option has no default to show (servo's id was "INT=-1 REQUIRED").
out=$("$animrt" servo --help 2>&1) || fail "servo --help failed: $out"
[[ $out == *"--id INT REQUIRED"* ]] || fail "servo --help shows a default for the required id: $out"

out=$("$animrt" seq train --help 2>&1) || fail "seq train --help failed: $out"
[[ $out == *"Usage: animrt seq train "* ]] || fail "seq train --help names another program: $out"
echo "ok"
