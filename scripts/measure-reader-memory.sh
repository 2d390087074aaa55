#!/usr/bin/env bash
# Peak memory (max RSS, /usr/bin/time -v) of each file reader on its worst
# malformed input, through the CLI: FIFOs, /dev/zero, gzip bombs, headers
# that lie about their counts, and the largest plain file each reader takes.
# Prints a Markdown table: input, its size, the exit code, max RSS, and the
# first error line (cut to 100 characters).
# Usage: scripts/measure-reader-memory.sh ANIMRT [WORKDIR]
set -uo pipefail
animrt=${1:?usage: measure-reader-memory.sh ANIMRT [WORKDIR]}
work=${2:-$(mktemp -d)}
mkdir -p "$work"
cd "$work" || exit 1

# Zeros as one gzip stream, written chunk by chunk.
gzip_zeros() {  # FILE MIB
  python3 - "$1" "$2" <<'PY'
import sys, zlib
out = open(sys.argv[1], "wb")
z = zlib.compressobj(9, zlib.DEFLATED, 31)
chunk = bytes(1 << 20)
for _ in range(int(sys.argv[2])):
    out.write(z.compress(chunk))
out.write(z.flush())
PY
}

[ -e bomb.obj.gz ] || gzip_zeros bomb.obj.gz 2048
[ -e bomb.md3.gz ] || cp bomb.obj.gz bomb.md3.gz
[ -e bomb.feat ] || cp bomb.obj.gz bomb.feat
[ -e bomb.model ] || cp bomb.obj.gz bomb.model
ln -sf /dev/zero zero.obj
ln -sf /dev/zero zero.model
rm -f pipe.obj pipe.model pipe.csv && mkfifo pipe.obj pipe.model pipe.csv
# 60 MiB of "v 0 0 0" lines: the largest plain OBJ the reader takes, all
# vertices, no faces.
[ -e vertices.obj ] || python3 -c "
import sys
sys.stdout.buffer.write(b'v 0 0 0\n' * (60 * 1024 * 1024 // 8))" >vertices.obj
# One number of 60 MB in an OBJ: the error line must not repeat it.
[ -e long_number.obj ] || python3 -c "
import sys
sys.stdout.write('v 0 0 ' + '7' * (60 * 1000 * 1000) + 'x\n')" >long_number.obj
# An MD2 header claiming 512 frames of 2048 vertices in 68 bytes.
python3 -c "
import struct, sys
sys.stdout.buffer.write(b'IDP2' + struct.pack('<16i', 8, 64, 64, 40 + 4 * 2048, 0, 2048, 0, 4096,
                                                0, 512, 68, 68, 68, 68, 68, 68))" >lying.md2
# A FLAC of 1 s whose STREAMINFO claims 2^28 frames, in a head robot file.
if [ ! -e lying.flac ]; then
  sox -n -r 16000 -c 1 -b 16 tone.flac synth 1 sine 150 2>/dev/null
  python3 -c "
b = bytearray(open('tone.flac', 'rb').read())
b[21] &= 0xf0
b[22:26] = bytes([0x10, 0, 0, 0])
open('lying.flac', 'wb').write(b)"
fi
# A 60 MB value in a YAML file.
[ -e long_value.yaml ] || python3 -c "
import sys
sys.stdout.write('name: ' + 'x' * (60 * 1000 * 1000) + '\n')" >long_value.yaml
# The largest value a YAML file may hold: one line of just under 4 MiB.
[ -e long_value_4mib.yaml ] || python3 -c "
import sys
sys.stdout.write('name: ' + 'x' * (4 * 1024 * 1024 - 7) + '\n')" >long_value_4mib.yaml
# The densest YAML: a flow list of as many nodes as a file may have (100000,
# the root map and its key included), and 4 MiB of block list items, refused
# at the node limit.
[ -e nodes_at_limit.yaml ] || python3 -c "
import sys
sys.stdout.write('name: [' + '0,' * (100000 - 4) + '0]\n')" >nodes_at_limit.yaml
[ -e tiny_items.yaml ] || python3 -c "
import sys
sys.stdout.write('name:\n' + '- 0\n' * (1024 * 1024 - 2))" >tiny_items.yaml

measure() {  # LABEL INPUT COMMAND...
  local label=$1 input=$2
  shift 2
  local size
  size=$(stat -Lc %s "$input" 2>/dev/null || echo "none")
  [ -p "$input" ] && size=FIFO
  [ -c "$input" ] && size=device
  timeout 60 /usr/bin/time -v -o time.txt "$@" >out.txt 2>err.txt
  local rc=$?
  local rss
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' time.txt)
  local line
  line=$(grep -v '^\s*$' err.txt | head -1 | cut -c1-100 | sed 's/|/\\|/g')
  local err_bytes
  err_bytes=$(wc -c <err.txt)
  printf '| %s | %s | %s | %s MiB | %s bytes: `%s` |\n' "$label" "$size" "$rc" \
    "$(awk -v k="${rss:-0}" 'BEGIN { printf "%.1f", k / 1024 }')" "$err_bytes" "$line"
}

echo "| input | size (bytes) | exit | max RSS | error output |"
echo "| --- | --- | --- | --- | --- |"
measure "baseline: a missing file" missing.obj "$animrt" seq features missing.obj --out f.feat
measure "OBJ: FIFO" pipe.obj "$animrt" seq features pipe.obj --out f.feat
measure "OBJ: /dev/zero" zero.obj "$animrt" seq features zero.obj --out f.feat
measure "OBJ .gz: 2 GiB of zeros" bomb.obj.gz "$animrt" seq features bomb.obj.gz --out f.feat
measure "MD3 .gz: 2 GiB of zeros" bomb.md3.gz "$animrt" seq features bomb.md3.gz --out f.feat
measure "MD2: header claims 512 x 2048 vertices" lying.md2 "$animrt" seq features lying.md2 --out f.feat
measure "OBJ: 60 MiB of vertex lines" vertices.obj "$animrt" seq features vertices.obj --out f.feat
measure "OBJ: one 60 MB number" long_number.obj "$animrt" seq features long_number.obj --out f.feat
measure "feature file: gzip bomb" bomb.feat "$animrt" seq reconstruct bomb.feat --out frames
measure "model: FIFO" pipe.model "$animrt" seq generate pipe.model --init x.obj --frames 2 --out g
measure "model: /dev/zero" zero.model "$animrt" seq generate zero.model --init x.obj --frames 2 --out g
measure "model: gzip bomb" bomb.model "$animrt" seq generate bomb.model --init x.obj --frames 2 --out g
measure "FLAC: header claims 2^28 frames" lying.flac "$animrt" head features lying.flac --out f.csv
measure "YAML: 60 MB value" long_value.yaml "$animrt" validate long_value.yaml
measure "YAML: one 4 MiB value" long_value_4mib.yaml "$animrt" validate long_value_4mib.yaml
measure "YAML: 100000 nodes in a flow list" nodes_at_limit.yaml "$animrt" validate nodes_at_limit.yaml
measure "YAML: 4 MiB of list items" tiny_items.yaml "$animrt" validate tiny_items.yaml
