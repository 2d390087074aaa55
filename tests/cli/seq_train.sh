#!/usr/bin/env bash
# animrt seq train on a tiny joint-angle CSV: exit code, progress lines,
# model, checkpoint and plot written, a resume from the checkpoint, and bad
# input refused with exit 2 and the file named.
set -uo pipefail
animrt=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

awk 'BEGIN { print "time_s,hip,knee,torso_x";
  for (f = 0; f < 60; f++) { t = f / 25; printf "%g,%g,%g,%g\n", t, 0.5 * sin(7.85 * t), 0.3 * cos(7.85 * t), t } }' \
  > "$tmp/walk.csv"
small=(--window 8 --batch 2 --hidden 16 --latent 8 --lstm-layers 2 --threads 1)

out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 10 --checkpoint-every 5 \
  --report-every 5 "${small[@]}" 2>&1) || fail "train failed: $out"
line='iteration 5/10  recon [0-9.e+-]+  bidir [0-9.e+-]+  KL [0-9.e+-]+  L2 [0-9.e+-]+  total [0-9.e+-]+  [0-9.]+ it/s  left [0-9]+:[0-9][0-9]'
[[ $out =~ $line ]] || fail "no progress line: $out"
[[ $out == *"iteration 10/10 "* ]] || fail "no last progress line: $out"
[[ $out == *"held-out reconstruction loss per frame"* ]] || fail "no held-out loss: $out"
for f in m.model m.model.ckpt m.model.svg; do
  [[ -s $tmp/$f ]] || fail "$f not written"
done
grep -q '<svg' "$tmp/m.model.svg" || fail "plot is not SVG"

out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/m.model" --iterations 14 --resume "$tmp/m.model.ckpt" \
  --report-every 2 "${small[@]}" 2>&1) || fail "resume failed: $out"
[[ $out == *"iteration 12/14 "* && $out == *"iteration 14/14 "* ]] || fail "resume did not continue: $out"
[[ $out != *"iteration 2/14 "* ]] || fail "resume started over: $out"
[[ $out == *"trained 4 iterations (14 in all)"* ]] || fail "resume count: $out"

printf 'ANSEQNN\nrubbish' > "$tmp/bad.ckpt"
out=$("$animrt" seq train "$tmp/walk.csv" --out "$tmp/n.model" --resume "$tmp/bad.ckpt" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "corrupt checkpoint: exit $code, expected 2: $out"
[[ $out == *"$tmp/bad.ckpt"* ]] || fail "corrupt checkpoint not named: $out"
[[ $(echo "$out" | wc -l) -eq 1 ]] || fail "more than one line: $out"

printf 'time_s,hip\n0,zero\n' > "$tmp/bad.csv"
out=$("$animrt" seq train "$tmp/bad.csv" --out "$tmp/n.model" 2>&1)
code=$?
[[ $code -eq 2 && $out == *"$tmp/bad.csv:2:3: hip:"* ]] || fail "bad CSV: exit $code: $out"
echo ok
