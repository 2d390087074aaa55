#!/usr/bin/env bash
# --backend hardware on a figure whose serial adapters are unplugged and
# whose drive's host does not answer: one error (exit 3, a device error)
# names every port that cannot be opened and the host that cannot be reached.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The animatronic figure (Dynamixel, Maestro, Modbus TCP) with neither of
# its two serial adapters plugged in and nothing listening at its drive's
# address (a TCP link is connected when the buses are configured).
sed -e "s#/dev/ttyUSB0#$tmp/no-neck-adapter#" -e "s#/dev/ttyACM0#$tmp/no-maestro#" \
  -e "s#192.168.1.50:502#127.0.0.1:1#" -e "s#\.\./#$root/configs/#g" \
  "$root/configs/robots/animatronic.yaml" > "$tmp/unplugged.yaml"
"$animrt" validate "$tmp/unplugged.yaml" > /dev/null 2>&1 || fail "the test's robot file is invalid"
out=$(timeout 60 "$animrt" run "$tmp/unplugged.yaml" --backend hardware --duration 1 --no-realtime \
  --no-audio 2>&1)
code=$?
[[ $code -eq 3 ]] || fail "exit code $code, expected 3: $out"
for port in "$tmp/no-neck-adapter" "$tmp/no-maestro" "127.0.0.1:1"; do
  [[ $out == *"$port"* ]] || fail "the error does not name $port: $out"
done
[[ $out == *"3 of 3 buses cannot be brought up"* ]] || fail "unexpected error: $out"
echo "ok"
