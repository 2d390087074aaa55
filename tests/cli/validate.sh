#!/usr/bin/env bash
# animrt validate: the shipped robot passes; a broken one fails with exit 2 and
# one message naming file, line, column and key.
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$animrt" validate "$root/configs/robots/quadruped.yaml" 2>&1) || fail "shipped config rejected: $out"
[[ $out == *": ok (12 joints, 1 bus, 12 devices"* ]] || fail "unexpected output: $out"

sed 's/^  rate_hz: .*/  rate_hz: fast/' "$root/configs/robots/quadruped.yaml" > "$tmp/bad.yaml"
sed -i "s#file: \.\./gaits/walk.yaml#file: $root/configs/gaits/walk.yaml#" "$tmp/bad.yaml"
out=$("$animrt" validate "$tmp/bad.yaml" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "exit code $code, expected 2: $out"
line=$(grep -n '^  rate_hz:' "$tmp/bad.yaml" | cut -d: -f1)
[[ $out == "error: $tmp/bad.yaml:$line:"*": loop.rate_hz: "*"fast"* ]] || fail "unexpected message: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

out=$("$animrt" validate "$tmp/missing.yaml" 2>&1)
[[ $? -eq 2 && $out == *"missing.yaml"*"cannot open"* ]] || fail "missing file: $out"
# One line per bus that has no device-side guard (or one set outside animrt).
out=$("$animrt" validate "$root/configs/robots/arm_sts.yaml" 2>&1) || fail "arm_sts rejected: $out"
[[ $(echo "$out" | grep -c "^bus arm (feetech_sts): no device-side guard") -eq 1 ]] ||
  fail "no guard line for the Feetech bus: $out"
out=$("$animrt" validate "$root/configs/robots/animatronic.yaml" 2>&1) || fail "animatronic rejected: $out"
[[ $(echo "$out" | grep -c "^bus torso (modbus-tcp): no device-side guard") -eq 1 &&
  $(echo "$out" | grep -c "^bus face (maestro): .*Timeout to 0.10 s in the Maestro Control Center") -eq 1 &&
  $(echo "$out" | grep -c "^bus neck") -eq 0 ]] || fail "guard lines of the animatronic figure: $out"
out=$("$animrt" validate "$root/configs/robots/quadruped.yaml" 2>&1)
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "the quadruped's Bus Watchdog is set by animrt: $out"
sed -e 's#^    timeout_ms: 4 .*#    timeout_ms: 4\n    device_watchdog_ms: "off"#' \
  -e "s#file: \.\./gaits/walk.yaml#file: $root/configs/gaits/walk.yaml#" \
  -e "s#model: \.\./#model: $root/configs/#" "$root/configs/robots/quadruped.yaml" > "$tmp/off.yaml"
out=$("$animrt" validate "$tmp/off.yaml" 2>&1) || fail "device_watchdog_ms: off rejected: $out"
[[ $out == *$'\n'"bus legs (dynamixel2): no device-side guard (device_watchdog_ms: off)"* ]] ||
  fail "device_watchdog_ms: off: $out"

# Every shipped robot validates (its motion sampled over its whole length).
for robot in "$root"/configs/robots/*.yaml; do
  out=$("$animrt" validate "$robot" 2>&1) || fail "shipped $robot rejected: $out"
done

# A device as the motion file: a clear error, not an endless read.
sed "s#file: \.\./gaits/walk.yaml#file: /dev/zero#" "$root/configs/robots/quadruped.yaml" > "$tmp/zero.yaml"
out=$(timeout 20 "$animrt" validate "$tmp/zero.yaml" 2>&1)
code=$?
line=$(grep -n 'file: /dev/zero' "$tmp/zero.yaml" | cut -d: -f1)
[[ $code -eq 2 && $out == "error: $tmp/zero.yaml:$line:9: motion.file: \"/dev/zero\" is not a regular file (character device)" ]] ||
  fail "/dev/zero as motion file (exit $code): $out"

# --duration of run and serve: a finite number of seconds >= 0, else a
# usage error (exit 1), in the same words (a serve with --duration nan ran
# until stopped).
for args in "run $root/configs/robots/quadruped.yaml" \
            "serve $root/configs/robots/animatronic.yaml --cues $root/configs/cues/animatronic.yaml"; do
  for bad in -1 nan -nan inf 1e400 soon; do
    # shellcheck disable=SC2086  # the words of $args are the arguments
    out=$(timeout 20 "$animrt" $args --duration "$bad" 2>&1)
    code=$?
    [[ $code -eq 1 ]] || fail "${args%% *} --duration $bad: exit $code, expected 1: $out"
    [[ $(echo "$out" | head -1) == "--duration: expected seconds from 0 (until stopped) to 31536000, found \"$bad\"" ]] ||
      fail "${args%% *} --duration $bad: unexpected message: $out"
  done
done
# Every bounded number refuses NaN, which compares as neither below nor above
# a bound.
for args in "run $root/configs/robots/quadruped.yaml --dashboard-rate" \
            "herd $root/configs/herd/flock.yaml --duration" \
            "head synth $root/configs/head/model.txt $root/configs/head/utterance.wav --noise-deg"; do
  for bad in nan -nan NaN; do
    # shellcheck disable=SC2086  # the words of $args are the arguments
    out=$(timeout 20 "$animrt" $args "$bad" 2>&1)
    code=$?
    option=${args##* }
    [[ $code -eq 1 && $(echo "$out" | head -1) == "$option: Value $bad is not a number" ]] ||
      fail "${args%% *} $option $bad: exit $code: $out"
  done
done
# Seeds are 0 to 2^63 - 1, as in the files: an unsigned option alone took -1
# as 2^64 - 1, and 2^63 passed a range over int64.
max_seed=9223372036854775807
for args in "herd $root/configs/herd/flock.yaml --seed" \
            "evolve $root/configs/evolve/horse_concatenating.yaml --seed" \
            "head corpus --out $tmp/corpus --seed" "seq corpus --out $tmp/corpus --seed" \
            "seq complete $tmp/model --seed" "seq generate $tmp/model --out $tmp/x --random-state"; do
  for bad in -1 9223372036854775808 1e3 0x10; do
    # shellcheck disable=SC2086  # the words of $args are the arguments
    out=$(timeout 20 "$animrt" $args "$bad" 2>&1)
    code=$?
    option=${args##* }
    [[ $code -eq 1 && $(echo "$out" | head -1) == "$option: Value $bad is not a seed (an integer from 0 to $max_seed)" ]] ||
      fail "${args%% *} $option $bad: exit $code: $out"
  done
done
out=$("$animrt" herd "$root/configs/herd/gate.yaml" --quiet --duration 1 --seed $max_seed 2>&1) ||
  fail "herd --seed $max_seed: $out"
# Output paths are checked when the command line is read, not after the work
# (an evolution, a training, a run): a folder where a file goes, a missing
# folder (where the command does not make it), a file where a folder goes.
touch "$tmp/a_file"
while IFS='|' read -r option path problem args; do
  # shellcheck disable=SC2086  # the words of $args are the arguments
  out=$(timeout 20 "$animrt" $args "$option" "$path" 2>&1)
  code=$?
  [[ $code -eq 1 && $(echo "$out" | head -1) == "$option: $path: $problem" ]] ||
    fail "${args%% *} $option $path: exit $code: $out"
done <<CASES
--out|$tmp|is a folder, expected a file to write|evolve $root/configs/evolve/quadruped_sinusoidal.yaml
--out|$tmp/none/g.yaml|its folder "$tmp/none" does not exist|evolve $root/configs/evolve/quadruped_sinusoidal.yaml
--out|$tmp/a_file|is a file, expected a folder|evolve $root/configs/evolve/quadruped_sinusoidal.yaml --pareto
--csv|$tmp|is a folder, expected a file to write|evolve $root/configs/evolve/quadruped_sinusoidal.yaml --out $tmp/g.yaml
--plot|$tmp/none/p.svg|its folder "$tmp/none" does not exist|evolve $root/configs/evolve/quadruped_sinusoidal.yaml --out $tmp/g.yaml
--out|$tmp/a_file/c.yaml|"$tmp/a_file" is a file, not a folder|gait calibrate $root/configs/robots/quadruped.yaml
--out|$tmp/none/c.yaml|its folder "$tmp/none" does not exist|gait calibrate $root/configs/robots/quadruped.yaml --physics $root/configs/models/quadruped.xml
--out|$tmp/none/t.md|its folder "$tmp/none" does not exist|head table $root/configs/head
--out|$tmp|is a folder, expected a file to write|head train $root/configs/head
--out|$tmp/a_file|is a file, expected a folder|head corpus
--out|$tmp/none/f.bin|its folder "$tmp/none" does not exist|seq features $tmp/clip
--out|$tmp/a_file/frames|"$tmp/a_file" is a file, not a folder|seq reconstruct $tmp/f.bin $tmp/m.obj
--telemetry|$tmp/none/t.csv|its folder "$tmp/none" does not exist|run $root/configs/robots/quadruped.yaml
--record|$tmp|is a folder, expected a file to write|run $root/configs/robots/quadruped.yaml
--write-robot|$tmp|is a folder, expected a file to write|scan $tmp/no_port
CASES
# The files written beside an output are checked before the work too (a
# folder where evolve's plot goes lost the search's gait after it; one where
# a gait's calibration goes, the whole grid walked).
mkdir -p "$tmp/ev/g.svg" "$tmp/gc/pony.calibration.yaml"
out=$(timeout 20 "$animrt" evolve "$root/configs/evolve/quadruped_sinusoidal.yaml" --out "$tmp/ev/g.yaml" 2>&1)
[[ $? -eq 1 && $out == "--out's .svg: $tmp/ev/g.svg: is a folder, expected a file to write" && ! -e $tmp/ev/g.csv ]] ||
  fail "evolve with its plot's path a folder: $out"
cp "$root/configs/gaits/pony.yaml" "$tmp/gc/"
out=$(cd "$tmp/gc" && timeout 20 "$animrt" gait calibrate "$root/configs/robots/pony.yaml" \
  --physics "$root/configs/models/pony.xml" --gait pony.yaml 2>&1)
[[ $? -eq 1 && $out == *"the calibration file pony.calibration.yaml: is a folder, expected a file to write (give another with --out)" ]] ||
  fail "gait calibrate with its default output a folder: $out"
# Any other parse error is a usage error too (CLI11's own codes are 100 and up).
out=$("$animrt" run 2>&1)
code=$?
[[ $code -eq 1 && $out == *"CONFIG is required"* ]] || fail "missing argument: exit $code: $out"
out=$("$animrt" validate a.yaml --bogus 2>&1)
code=$?
[[ $code -eq 1 ]] || fail "unknown option: exit $code: $out"
out=$("$animrt" --help 2>&1)
[[ $? -eq 0 && $out == *"validate"* ]] || fail "--help: $out"
echo "validate: ok"
