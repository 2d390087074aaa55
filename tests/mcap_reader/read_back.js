// Reads an MCAP recording of `animrt run --record` with the MCAP project's
// own TypeScript reader (@mcap/core) and a zstd decoder of its own (fzstd),
// and checks it against the run's CSV telemetry and JSON summary:
//   node read_back.js RUN.mcap RUN.csv SUMMARY.json
// Prints what is wrong and exits 1, or prints one line and exits 0.
"use strict";
const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const fzstd = require("fzstd");

const [mcapPath, csvPath, summaryPath] = process.argv.slice(2);
const bytes = new Uint8Array(fs.readFileSync(mcapPath));
const csv = fs.readFileSync(csvPath, "utf8").trim().split("\n").map((l) => l.split(","));
const summary = JSON.parse(fs.readFileSync(summaryPath, "utf8"));
const decompressHandlers = { zstd: (buf, size) => fzstd.decompress(buf, new Uint8Array(Number(size))) };
const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
};

async function main() {
  // The indexed reader: footer, summary (its CRC), statistics, chunk indexes.
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  check(reader.footer.summaryCrc !== 0, "the footer has no summary CRC");
  check(reader.statistics !== undefined, "no Statistics record in the summary");
  check(reader.chunkIndexes.length > 0, "no Chunk Index records");
  check(
    reader.chunkIndexes.every((c) => c.compression === "zstd"),
    "a chunk is not zstd-compressed",
  );
  const topics = new Map();
  for (const ch of reader.channelsById.values()) topics.set(ch.topic, ch);
  const schemaOf = (topic) => reader.schemasById.get(topics.get(topic)?.schemaId)?.name;
  check(schemaOf("/joint_states") === "foxglove.JointStates", "/joint_states is not foxglove.JointStates");
  check(schemaOf("/joint_commands") === "foxglove.JointStates", "/joint_commands is not foxglove.JointStates");
  check(schemaOf("/events") === "foxglove.Log", "/events is not foxglove.Log");
  check(schemaOf("/loop") === "animrt.LoopStats", "/loop is not animrt.LoopStats");
  const devices = [...topics.keys()].filter((t) => /^\/devices\/[^/]+\/[^/]+\/status$/.test(t));
  check(devices.length === summary.devices.length, `${devices.length} device status channels`);
  for (const ch of topics.values()) {
    check(ch.messageEncoding === "json", `${ch.topic} is not json`);
    const schema = reader.schemasById.get(ch.schemaId);
    check(schema && schema.encoding === "jsonschema", `${ch.topic}'s schema is not a jsonschema`);
  }

  // Every message through the indexed reader (chunk CRCs checked), and the
  // data section's CRC over the file's bytes up to Data End.
  const counts = new Map();
  const states = [];
  const events = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const topic = reader.channelsById.get(m.channelId).topic;
    counts.set(topic, (counts.get(topic) ?? 0) + 1);
    const msg = JSON.parse(new TextDecoder().decode(m.data));
    if (topic === "/joint_states") states.push({ t: m.logTime, msg });
    if (topic === "/events") events.push(msg);
  }
  let dataEnd;
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  let offset = 8;
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "DataEnd") dataEnd = r;
  }
  check(stream.done(), "the stream reader did not reach the footer");
  check(dataEnd && dataEnd.dataSectionCrc !== 0, "no data section CRC");
  if (dataEnd) {
    const dataEndOffset = Number(reader.footer.summaryStart) - 13;
    check(crc32(bytes.subarray(0, dataEndOffset)) === dataEnd.dataSectionCrc, "data section CRC does not match");
  }

  const stats = reader.statistics;
  const total = [...counts.values()].reduce((a, b) => a + b, 0);
  check(BigInt(total) === stats.messageCount, `statistics count ${stats.messageCount}, read ${total}`);
  check(stats.channelCount === topics.size, "statistics channel count");
  check(counts.get("/joint_states") === summary.cycles, `${counts.get("/joint_states")} joint states for ${summary.cycles} cycles`);
  check(counts.get("/joint_commands") === summary.cycles, `${counts.get("/joint_commands")} joint commands for ${summary.cycles} cycles`);
  check(counts.get("/loop") === summary.cycles, `${counts.get("/loop")} loop records for ${summary.cycles} cycles`);
  check(BigInt(total) === BigInt(summary.recording.messages), "the summary's message count");
  check(events.some((e) => e.message === "motion started" && e.level === 2), "no motion started event");
  check(events.some((e) => /^run ended: duration/.test(e.message)), "no run ended event");

  // A joint's measured position at the same time as the CSV's row.
  const header = csv[0];
  const rows = csv.slice(1).map((r) => r.map(Number));
  check(rows.length === states.length, `${rows.length} CSV rows, ${states.length} joint states`);
  const t0 = states[0].t;
  for (const k of [Math.floor(states.length / 2), states.length - 1]) {
    const s = states[k];
    const t = Number(s.t - t0) * 1e-9;
    const row = rows.find((r) => Math.abs(r[0] - t) < 1e-6);
    check(row !== undefined, `no CSV row at t=${t}`);
    if (!row) continue;
    for (const joint of s.msg.joints) {
      const col = header.indexOf(`${joint.name}_meas_rad`);
      check(col > 0, `no CSV column for ${joint.name}`);
      check(Math.abs(row[col] - joint.position) < 1e-7, `${joint.name} at t=${t}: ${joint.position} vs CSV ${row[col]}`);
    }
    const stamp = BigInt(s.msg.timestamp.sec) * 1000000000n + BigInt(s.msg.timestamp.nsec);
    check(stamp === s.t, "a JointStates timestamp is not its log time");
  }
  if (failures.length) {
    console.log("FAIL:\n  " + failures.join("\n  "));
    process.exit(1);
  }
  console.log(`ok: ${total} messages on ${topics.size} channels in ${reader.chunkIndexes.length} chunks`);
}

main().catch((e) => {
  console.log(`FAIL: ${e.message}`);
  process.exit(1);
});
