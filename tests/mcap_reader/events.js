// Prints the /events messages of an MCAP recording, one "LEVEL MESSAGE" a
// line, read with @mcap/core: node events.js RUN.mcap
"use strict";
const fs = require("fs");
const { McapIndexedReader } = require("@mcap/core");
const fzstd = require("fzstd");

async function main() {
  const bytes = new Uint8Array(fs.readFileSync(process.argv[2]));
  const reader = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt(bytes.length),
      read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
    },
    decompressHandlers: { zstd: (buf, size) => fzstd.decompress(buf, new Uint8Array(Number(size))) },
  });
  for await (const m of reader.readMessages({ topics: ["/events"], validateCrcs: true })) {
    const log = JSON.parse(new TextDecoder().decode(m.data));
    console.log(`${log.level} ${log.message}`);
  }
}

main().catch((e) => {
  console.log(`FAIL: ${e.message}`);
  process.exit(1);
});
