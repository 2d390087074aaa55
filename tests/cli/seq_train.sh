#!/usr/bin/env bash
# animrt seq train on a tiny joint-angle CSV: exit code, progress lines,
# model, checkpoint and plot written, a resume from the checkpoint (a
# truncated best model beside it set aside), and bad input refused with
# exit 2 and the file named; then a mesh model trained on a bending plate
# and seq generate from it.
set -uo pipefail
animrt=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

source "$(dirname "$0")/seq_data.bash"
write_walk_csv "$tmp/walk.csv"

out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 10 --checkpoint-every 5 \
  --report-every 5 --clip-gradient 1e-6 "${small[@]}" 2>&1) || fail "train failed: $out"
[[ $out == *"gradient clipped to 1e-06 in 10 of 10 iterations (largest norm "* ]] ||
  fail "no clipping line: $out"
[[ $out == *"best held-out completion: iteration 10, kept in $tmp/m.model.best"* ]] ||
  fail "no best model line: $out"
line='iteration 5/10  recon [0-9.e+-]+  bidir [0-9.e+-]+  KL [0-9.e+-]+  L2 [0-9.e+-]+  total [0-9.e+-]+  [0-9.]+ it/s  left [0-9]+:[0-9][0-9]'
[[ $out =~ $line ]] || fail "no progress line: $out"
[[ $out == *"iteration 10/10 "* ]] || fail "no last progress line: $out"
[[ $out == *"held-out reconstruction loss per frame"* ]] || fail "no held-out loss: $out"
for f in m.model m.model.ckpt m.model.svg m.model.best; do
  [[ -s $tmp/$f ]] || fail "$f not written"
done
grep -q '<svg' "$tmp/m.model.svg" || fail "plot is not SVG"

# A truncated best model is set aside, not taken for the model in training.
head -c 100 "$tmp/m.model.best" > "$tmp/cut.best"
mv "$tmp/cut.best" "$tmp/m.model.best"
out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 14 --resume "$tmp/m.model.ckpt" \
  --report-every 2 "${small[@]}" 2>&1) || fail "resume failed: $out"
[[ $out == *"note: $tmp/m.model.best is not a best model of this training: cannot be read: "*"; moved to $tmp/m.model.best.stale"* ]] ||
  fail "truncated best model not set aside: $out"
[[ $(wc -c < "$tmp/m.model.best.stale") -eq 100 ]] || fail "the set-aside best model is not the truncated one"
[[ $out == *"best held-out completion: iteration 14, kept in $tmp/m.model.best"* ]] ||
  fail "no best model after the set-aside one: $out"
[[ $out == *"iteration 12/14 "* && $out == *"iteration 14/14 "* ]] || fail "resume did not continue: $out"
[[ $out != *"iteration 2/14 "* ]] || fail "resume started over: $out"
[[ $out == *"trained 4 iterations (14 in all)"* ]] || fail "resume count: $out"

printf 'ANSEQNN\nrubbish' > "$tmp/bad.ckpt"
out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/n.model" --resume "$tmp/bad.ckpt" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "corrupt checkpoint: exit $code, expected 2: $out"
[[ $out == *"$tmp/bad.ckpt"* ]] || fail "corrupt checkpoint not named: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/n.model" --placement-weight 0 2>&1) &&
  fail "placement weight 0 accepted: $out"
[[ $out == *"--placement-weight"* ]] || fail "placement weight 0 not named: $out"
out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/n.model" --clip-gradient -1 2>&1) &&
  fail "negative clip accepted: $out"
[[ $out == *"--clip-gradient"* ]] || fail "negative clip not named: $out"

printf 'time_s,hip\n0,zero\n' > "$tmp/bad.csv"
out=$("$animrt" seq train "$tmp/bad.csv" --out "$tmp/n.model" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/bad.csv:2:3: hip:"* ]] || fail "bad CSV: exit $code: $out"
# A 6 x 6 plate bending to and fro, 30 OBJ frames.
write_plate "$tmp/plate"
"$animrt" seq features "$tmp/plate" --out "$tmp/plate.bin" >/dev/null || fail "features of the plate"
out=$("$animrt" seq train "$tmp/plate.bin" --out "$tmp/plate.model" --iterations 4 "${small[@]}" 2>&1) ||
  fail "mesh training failed: $out"
out=$("$animrt" seq generate "$tmp/plate.model" --init "$tmp/plate/frame_0000.obj" "$tmp/plate/frame_0001.obj" \
  --frames 12 --out "$tmp/gen" 2>&1) || fail "generate failed: $out"
[[ $(ls "$tmp/gen" | wc -l) -eq 14 ]] || fail "generate wrote $(ls "$tmp/gen" | wc -l) frames, expected 14"
cmp -s <(grep '^v ' "$tmp/gen/frame_0000.obj") <(grep '^v ' "$tmp/gen/frame_0013.obj") &&
  fail "the last generated frame has the first frame's vertices"
cmp -s <(grep '^v ' "$tmp/gen/frame_0001.obj") <(grep '^v ' "$tmp/plate/frame_0001.obj") ||
  fail "the second initial frame is not kept"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$tmp/other.obj"
out=$("$animrt" seq generate "$tmp/plate.model" --init "$tmp/other.obj" --frames 2 --out "$tmp/gen2" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/plate.model: mesh: trained on a mesh of 36 vertices, the data has 3"* ]] ||
  fail "other mesh: exit $code: $out"
echo ok
