#!/usr/bin/env bash
# Regenerates the bundled head files: a short utterance spoken by espeak-ng
# (utterance.wav) and a small model trained by our own trainer on a generated
# corpus (model.txt). Usage: configs/head/make_bundle.sh [path/to/animrt]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
animrt="${1:-$here/../../build/bin/animrt}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

espeak-ng -v en-us+m3 -p 45 -s 155 -m -w "$here/utterance.wav" \
  '<speak>Hello! I am the <emphasis level="strong">talking</emphasis> head. Do you <prosody pitch="+30%">really</prosody> believe that I can <emphasis>move</emphasis> like this?</speak>'

"$animrt" head corpus --out "$work/corpus" --utterances 40 --speakers 4 --seed 1 --quiet
"$animrt" head train "$work/corpus" --out "$here/model.txt" -K 16 -S 3 -M 2 --topology LR --seed 1 --quiet
"$animrt" head eval "$here/model.txt" "$work/corpus"
