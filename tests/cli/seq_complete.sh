#!/usr/bin/env bash
# animrt seq complete and seq generate on tiny trained models, run by animrt
# itself (which must not link libtorch): keys reproduced exactly, the per-gap
# report printed, joint-space generation from a CSV, a model of another
# joint set and a corrupt model refused with exit 2 and one line naming the
# file; then completion between OBJ keys with a mesh model, two folders as
# one feature file of two clips, and seq evaluate on a model trained on it
# (--held-out and --held-out-clip together refused).
set -uo pipefail
animrt=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

libs=$(ldd "$animrt") || fail "ldd $animrt"
[[ $libs == *torch* ]] && fail "animrt links libtorch: $(grep torch <<< "$libs")"

source "$(dirname "$0")/seq_data.bash"
write_walk_csv "$tmp/walk.csv"
train_out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 10 --report-every 10 \
  "${small[@]}" 2>&1) || fail "train failed: $train_out"

printf 'time_s,hip,knee\n0,0.25,-0.125\n1,-0.4,0.3\n2,0.1,0.2\n' > "$tmp/keys.csv"
out=$("$animrt" seq complete "$tmp/m.model" --keys "$tmp/keys.csv" --gap 4 --out "$tmp/done.csv" 2>&1) ||
  fail "complete failed: $out"
gap='gap 1 \(keys 1-2, 4 frames\): (merged at frame [1-4] \(output frame [1-4]\), difference [0-9.]+ %, [0-9]+ tr(y|ies)|not merged below 5 %, best difference [0-9.]+ % at frame [1-4] \(output frame [1-4]\) used, 21 tries)'
[[ $out =~ $gap ]] || fail "no report for gap 1: $out"
# Training ended with a held-out line; completion warns exactly when that
# line says the model lost to linear interpolation.
[[ $train_out =~ held\ out\ at\ iteration\ 10:\ completion\ of\ 9-frame\ gaps\ [0-9.]+\ %,\ linear\ interpolation\ [0-9.]+\ %\ \([0-9]+\ %\ (better|worse)\ than\ interpolation\) ]] ||
  fail "no held-out line: $train_out"
if [[ ${BASH_REMATCH[1]} == worse ]]; then
  [[ $out == *"warning: $tmp/m.model: never measured better than linear interpolation on held-out data ("*"10 iterations); train it longer"* ]] ||
    fail "no warning for a model worse than interpolation: $out"
else
  [[ $out != *warning* ]] || fail "a warning for a model better than interpolation: $out"
fi
[[ $out == *"gap 2 (keys 2-3, 4 frames): "* ]] || fail "no report for gap 2: $out"
[[ $(head -1 "$tmp/done.csv") == "hip,knee" ]] || fail "header: $(head -1 "$tmp/done.csv")"
[[ $(wc -l < "$tmp/done.csv") -eq 12 ]] || fail "$(wc -l < "$tmp/done.csv") lines, expected 1 + 11"
[[ $(sed -n 2p "$tmp/done.csv") == "0.25,-0.125" ]] || fail "key 1: $(sed -n 2p "$tmp/done.csv")"
[[ $(sed -n 7p "$tmp/done.csv") == "-0.4,0.3" ]] || fail "key 2: $(sed -n 7p "$tmp/done.csv")"
[[ $(sed -n 12p "$tmp/done.csv") == "0.1,0.2" ]] || fail "key 3: $(sed -n 12p "$tmp/done.csv")"
[[ $(sed -n 4p "$tmp/done.csv") != "0.25,-0.125" ]] || fail "an in-between is a copy of the key"

# A tiny threshold: every gap retried up to the limit, and said so.
out=$("$animrt" seq complete "$tmp/m.model" --keys "$tmp/keys.csv" --gap 4 --out "$tmp/done2.csv" \
  --threshold 1e-9 --retries 3 --seed 5 2>&1) || fail "complete with a tiny threshold failed: $out"
[[ $out == *"gap 1 (keys 1-2, 4 frames): not merged below 1e-07 %, best difference"*"used, 4 tries"* ]] ||
  fail "no retries reported: $out"

out=$("$animrt" seq generate "$tmp/m.model" --init "$tmp/keys.csv" --frames 9 --out "$tmp/gen.csv" 2>&1) ||
  fail "joint generate failed: $out"
[[ $(wc -l < "$tmp/gen.csv") -eq 13 ]] || fail "generate wrote $(wc -l < "$tmp/gen.csv") lines, expected 1 + 12"
[[ $(sed -n 2,4p "$tmp/gen.csv") == $'0.25,-0.125\n-0.4,0.3\n0.1,0.2' ]] || fail "initial frames not kept"

printf 'hip,ankle\n0,0\n1,1\n' > "$tmp/other.csv"
out=$("$animrt" seq complete "$tmp/m.model" --keys "$tmp/other.csv" --gap 4 --out "$tmp/x.csv" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/m.model: joints: trained on another joint set: the data lacks knee; the model lacks ankle"* ]] ||
  fail "other joint set: exit $code: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

printf 'ANSEQNN\nrubbish' > "$tmp/bad.model"
out=$("$animrt" seq complete "$tmp/bad.model" --keys "$tmp/keys.csv" --gap 4 --out "$tmp/x.csv" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/bad.model"* ]] || fail "corrupt model: exit $code: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

printf 'time_s,hip,knee\n0,0.25,-0.125\n' > "$tmp/one.csv"
out=$("$animrt" seq complete "$tmp/m.model" --keys "$tmp/one.csv" --gap 4 --out "$tmp/x.csv" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/one.csv: --keys: 1 rows, at least 2 needed"* ]] || fail "one key: exit $code: $out"

# A key or an initial frame far outside the model's training range is
# refused at its line before anything is written (1e300 came back as a
# generated file's first row).
printf 'time_s,hip,knee\n# a comment\n0,0.25,-0.125\n1,1e300,0.3\n' > "$tmp/far.csv"
for cmd in "complete --gap 4 --keys" "generate --init"; do
  rm -f "$tmp/far_out.csv"
  out=$("$animrt" seq ${cmd%% *} "$tmp/m.model" ${cmd#* } "$tmp/far.csv" --out "$tmp/far_out.csv" 2>&1)
  code=$?
  [[ $code -eq 2 && $out == "error: $tmp/far.csv:4: hip: 1e+300 is far outside the range $tmp/m.model was trained on ("* ]] ||
    fail "$cmd, a 1e300 angle: exit $code: $out"
  [[ $(echo "$out" | wc -l) -eq 1 && ! -e $tmp/far_out.csv ]] || fail "$cmd, a 1e300 angle: $out"
done

# A 6 x 6 plate bending to and fro, 30 OBJ frames; keys 0, 10 and 20.
write_plate "$tmp/plate"
"$animrt" seq features "$tmp/plate" --out "$tmp/plate.bin" >/dev/null || fail "features of the plate"
out=$("$animrt" seq train "$tmp/plate.bin" --out "$tmp/plate.model" --iterations 4 "${small[@]}" 2>&1) ||
  fail "mesh training failed: $out"
out=$("$animrt" seq complete "$tmp/plate.model" --keys "$tmp/plate/frame_0000.obj" "$tmp/plate/frame_0010.obj" \
  "$tmp/plate/frame_0020.obj" --gap 3 --out "$tmp/filled" 2>&1) || fail "mesh complete failed: $out"
[[ $out == *"gap 2 (keys 2-3, 3 frames): "* ]] || fail "no mesh report: $out"
[[ $(ls "$tmp/filled" | wc -l) -eq 9 ]] || fail "complete wrote $(ls "$tmp/filled" | wc -l) frames, expected 9"
for pair in 0000:0000 0004:0010 0008:0020; do
  cmp -s <(grep '^v ' "$tmp/filled/frame_${pair%:*}.obj") <(grep '^v ' "$tmp/plate/frame_${pair#*:}.obj") ||
    fail "key ${pair#*:} is not reproduced as frame ${pair%:*}"
done
cmp -s <(grep '^v ' "$tmp/filled/frame_0002.obj") <(grep '^v ' "$tmp/filled/frame_0000.obj") &&
  fail "an in-between mesh is a copy of the key"
# A key may flatten a triangle, as a game pose can (frame 28 of sydney.md2):
# it is measured against the model's template. Vertex 2 onto vertex 1
# flattens the triangle 1 7 2.
awk '/^v / { n++; if (n == 1) first = $0; if (n == 2) { print first; next } } { print }' \
  "$tmp/plate/frame_0010.obj" > "$tmp/flat.obj"
out=$("$animrt" seq complete "$tmp/plate.model" --keys "$tmp/plate/frame_0000.obj" "$tmp/flat.obj" \
  --gap 2 --out "$tmp/f3" 2>&1) || fail "a key with a flattened triangle was refused: $out"
[[ $(ls "$tmp/f3" | wc -l) -eq 4 ]] || fail "complete wrote $(ls "$tmp/f3" | wc -l) frames, expected 4"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$tmp/other.obj"
out=$("$animrt" seq complete "$tmp/plate.model" --keys "$tmp/other.obj" "$tmp/other.obj" --gap 2 --out "$tmp/f2" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/plate.model: mesh: trained on a mesh of 36 vertices, the data has 3"* ]] ||
  fail "other mesh: exit $code: $out"

# Two folders as one feature file, a clip each; a model trained on it
# measured on its held-out frames.
mkdir "$tmp/plate_a" "$tmp/plate_b"
for f in $(seq 0 29); do
  n=$(printf %04d "$f")
  if ((f < 15)); then cp "$tmp/plate/frame_$n.obj" "$tmp/plate_a/"; else cp "$tmp/plate/frame_$n.obj" "$tmp/plate_b/"; fi
done
out=$("$animrt" seq features "$tmp/plate_a" "$tmp/plate_b" --out "$tmp/two.bin" 2>&1) || fail "features of two folders: $out"
[[ $out == *"2 inputs: 36 vertices, 50 triangles, frames 0..29"* && $out == *"clip plate_a "*"15 frames"* &&
  $out == *"clip plate_b "*"15 frames"* ]] || fail "two folders: $out"
# Folders given with a trailing slash are named after the folder all the same.
out=$("$animrt" seq features "$tmp/plate_a/" "$tmp/plate_b/" --out "$tmp/slash.bin" 2>&1) ||
  fail "features of two folders with trailing slashes: $out"
[[ $out == *"clip plate_a "*"15 frames"* && $out == *"clip plate_b "*"15 frames"* ]] ||
  fail "trailing slash: $out"
out=$("$animrt" seq features "$tmp/plate_a" "$tmp/plate_b" --clip plate_a --out "$tmp/bad.bin" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/plate_a: --clip: --clip takes one input, not 2"* ]] ||
  fail "--clip with two inputs: exit $code: $out"
out=$("$animrt" seq features "$tmp/plate_a" "$tmp/other.obj" --out "$tmp/bad.bin" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/other.obj: connectivity: differs from $tmp/plate_a"* ]] ||
  fail "other connectivity: exit $code: $out"
out=$("$animrt" seq train "$tmp/two.bin" --out "$tmp/two.model" --iterations 2 --seed 4 "${small[@]}" 2>&1) ||
  fail "training on two clips failed: $out"
out=$("$animrt" seq evaluate "$tmp/two.model" "$tmp/two.bin" --gap 1 --change-frames 3 2>&1) ||
  fail "evaluate failed: $out"
[[ $out == *"2 iterations; held out (seed 4, 20 %): 6 of 30 frames"* && $out == *"complete "*" gaps of 1 frames"* &&
  $out == *"generated t = 1..3: "* ]] || fail "evaluate: $out"
# The held-out fraction and named clips are two ways to say the same
# thing: both together are refused with one error naming both.
out=$("$animrt" seq evaluate "$tmp/two.model" "$tmp/two.bin" --held-out 0.2 --held-out-clip plate_a 2>&1)
code=$?
first=$(echo "$out" | head -1)
[[ $code -eq 1 && ($first == "--held-out excludes --held-out-clip" || $first == "--held-out-clip excludes --held-out") ]] ||
  fail "--held-out with --held-out-clip: exit $code: $out"
"$animrt" seq features "$tmp/plate_b" --out "$tmp/b.bin" >/dev/null || fail "features of plate_b"
out=$("$animrt" seq evaluate "$tmp/plate.model" "$tmp/b.bin" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/plate.model: template: trained on another template"* ]] ||
  fail "other template: exit $code: $out"

# A show with learned in-betweens: validate warns when its model lost to
# interpolation on held-out data, and only then.
mkdir "$tmp/robots"
awk 'BEGIN { print "time_s,eye_pan,eye_tilt";
  for (f = 0; f < 60; f++) { t = f / 25; printf "%g,%g,%g\n", t, 0.3 * sin(7.85 * t), 0.2 * cos(7.85 * t) } }' \
  > "$tmp/eyes.csv"
train_out=$("$animrt" seq train "$tmp/eyes.csv" --out "$tmp/eyes.model" --iterations 10 "${small[@]}" 2>&1) ||
  fail "training the eyes failed: $train_out"
printf 'name: eyes\nlearned: {model: ../eyes.model, frame_s: 0.04}\njoints:\n  eye_pan: {interpolation: learned, keys: [[0, 0], [0.4, 10], [0.8, -10]]}\n  eye_tilt: {interpolation: learned, keys: [[0, 5], [0.4, 0], [0.8, 5]]}\n' \
  > "$tmp/robots/eyes.yaml"
sed -e "s#\.\./modbus/#$root/configs/modbus/#" -e '/^motion:/,$d' "$root/configs/robots/animatronic.yaml" > "$tmp/robots/r.yaml"
printf 'motion: {type: show, file: eyes.yaml}\n' >> "$tmp/robots/r.yaml"
out=$("$animrt" validate "$tmp/robots/r.yaml" 2>&1) || fail "validate of the learned show failed: $out"
[[ $train_out =~ held\ out\ at\ iteration\ 10:.*\ (better|worse)\ than\ interpolation\) ]] || fail "no held-out line: $train_out"
if [[ ${BASH_REMATCH[1]} == worse ]]; then
  [[ $out == *"warning: $tmp/robots/../eyes.model: never measured better than linear interpolation"* ]] ||
    fail "validate did not warn of the learned show's model: $out"
else
  [[ $out != *"never measured better"* ]] || fail "validate warned of a model better than interpolation: $out"
fi
echo ok
