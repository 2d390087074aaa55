// The MCAP writer's bytes against the specification's layout, laid out by
// hand for a tiny file; the reader's refusals; a recording read back as the
// viewer reads it.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/runtime/mcap_reader.hpp"
#include "animrt/runtime/mcap_recorder.hpp"
#include "animrt/runtime/mcap_writer.hpp"
#include "animrt/runtime/telemetry_replay.hpp"

namespace animrt {
namespace {

std::vector<std::uint8_t> mcap_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void mcap_write_file(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// Little-endian fields, appended as the specification lists them.
struct McapBytes {
  std::vector<std::uint8_t> b;
  McapBytes& u8(std::uint8_t v) {
    b.push_back(v);
    return *this;
  }
  McapBytes& le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  McapBytes& u16(std::uint64_t v) { return le(v, 2); }
  McapBytes& u32(std::uint64_t v) { return le(v, 4); }
  McapBytes& u64(std::uint64_t v) { return le(v, 8); }
  McapBytes& raw(const std::string& s) {
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  McapBytes& str(const std::string& s) { return u32(s.size()).raw(s); }
  McapBytes& add(const McapBytes& o) {
    b.insert(b.end(), o.b.begin(), o.b.end());
    return *this;
  }
  std::size_t size() const { return b.size(); }
};

TEST(McapCrc, IsTheIsoHdlcCrc32) {
  const std::string check = "123456789";
  EXPECT_EQ(mcap::crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}),
            0xCBF43926u);
  // Continued over two parts as over one.
  const auto* p = reinterpret_cast<const std::uint8_t*>(check.data());
  EXPECT_EQ(mcap::crc32({p + 4, 5}, mcap::crc32({p, 4})), 0xCBF43926u);
}

TEST(McapWriter, LaysOutATinyFileAsTheSpecificationSays) {
  const std::string path = ::testing::TempDir() + "mcap_layout.mcap";
  {
    mcap::WriterOptions options;
    options.compression = mcap::Compression::none;
    options.library = "t";
    mcap::Writer w(path, options);
    EXPECT_EQ(w.add_schema("S", "jsonschema", "{}"), 1);
    EXPECT_EQ(w.add_channel(1, "/a", "json"), 1);
    w.write(1, 7, 100, 100, "{}");
    w.close();
  }
  const std::vector<std::uint8_t> magic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  // Schema: id, name, encoding, data (27 bytes); Channel: id, schema id,
  // topic, message encoding, an empty map (22 bytes).
  McapBytes schema, channel, message;
  schema.u8(0x03).u64(27).u16(1).str("S").str("jsonschema").str("{}");
  channel.u8(0x04).u64(22).u16(1).u16(1).str("/a").str("json").u32(0);
  // Message: channel, sequence, log time, publish time, data (24 bytes).
  message.u8(0x05).u64(24).u16(1).u32(7).u64(100).u64(100).raw("{}");
  McapBytes records;
  records.add(schema).add(channel).add(message);
  ASSERT_EQ(records.size(), 100u);
  McapBytes f;
  f.b = magic;
  f.u8(0x01).u64(9).str("").str("t");  // Header: profile, library
  ASSERT_EQ(f.size(), 26u);
  // Chunk (at 26): start, end, uncompressed size and CRC, compression "",
  // the records' length and the records: 140 bytes.
  f.u8(0x06).u64(140).u64(100).u64(100).u64(100).u32(mcap::crc32(records.b)).str("");
  f.u64(100).add(records);
  ASSERT_EQ(f.size(), 175u);
  // Message Index (at 175): channel 1, one entry (time 100, at byte 67 of
  // the chunk's records: after the schema's 36 and the channel's 31).
  f.u8(0x07).u64(22).u16(1).u32(16).u64(100).u64(67);
  ASSERT_EQ(f.size(), 206u);
  // Data End: the CRC of every byte before it.
  const std::uint32_t data_crc = mcap::crc32(f.b);
  f.u8(0x0F).u64(4).u32(data_crc);
  // The summary (at 219): the schema and channel again, Statistics, the
  // Chunk Index, then a Summary Offset per group.
  const std::uint64_t summary = f.size();
  ASSERT_EQ(summary, 219u);
  McapBytes s;
  s.add(schema).add(channel);
  // Statistics: messages, schemas, channels, attachments, metadata, chunks,
  // start, end, per channel counts {1: 1}.
  s.u8(0x0B).u64(56).u64(1).u16(1).u32(1).u32(0).u32(0).u32(1).u64(100).u64(100);
  s.u32(10).u16(1).u64(1);
  // Chunk Index: start, end, chunk offset and length, message index
  // offsets {1: 175}, message index length, compression, sizes.
  s.u8(0x08).u64(74).u64(100).u64(100).u64(26).u64(149).u32(10).u16(1).u64(175).u64(31);
  s.str("").u64(100).u64(100);
  ASSERT_EQ(s.size(), 36u + 31 + 65 + 83);
  const std::uint64_t offsets = summary + s.size();
  s.u8(0x0E).u64(17).u8(0x03).u64(summary).u64(36);
  s.u8(0x0E).u64(17).u8(0x04).u64(summary + 36).u64(31);
  s.u8(0x0E).u64(17).u8(0x0B).u64(summary + 67).u64(65);
  s.u8(0x0E).u64(17).u8(0x08).u64(summary + 132).u64(83);
  // Footer: summary start, summary offset start, CRC from the summary's
  // start through the summary offset start field.
  s.u8(0x02).u64(20).u64(summary).u64(offsets);
  const std::uint32_t summary_crc = mcap::crc32(s.b);
  s.u32(summary_crc);
  f.add(s);
  f.b.insert(f.b.end(), magic.begin(), magic.end());

  const std::vector<std::uint8_t> got = mcap_file_bytes(path);
  ASSERT_EQ(got.size(), f.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i], f.b[i]) << "byte " << i;
  }
}

TEST(McapReader, RefusesAFileCutShortWithOneErrorNamingIt) {
  const std::string path = ::testing::TempDir() + "mcap_cut.mcap";
  {
    mcap::Writer w(path);
    const auto schema = w.add_schema("S", "jsonschema", "{}");
    const auto channel = w.add_channel(schema, "/a", "json");
    for (std::uint32_t i = 0; i < 100; ++i) w.write(channel, i, i, i, "{\"x\":1}");
  }
  const std::vector<std::uint8_t> whole = mcap_file_bytes(path);
  EXPECT_EQ(mcap::read_file(path).messages.size(), 100u);
  for (const std::size_t keep :
       {whole.size() - 1, whole.size() / 2, std::size_t{30}, std::size_t{5}}) {
    mcap_write_file(path, {whole.begin(), whole.begin() + static_cast<long>(keep)});
    try {
      (void)mcap::read_file(path);
      ADD_FAILURE() << "read a file cut to " << keep << " bytes";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      if (keep > 8) {
        EXPECT_NE(what.find("truncated"), std::string::npos) << what;
      }
    }
  }
  // A flipped byte in the chunk's compressed records or in the summary.
  std::vector<std::uint8_t> flipped = whole;
  flipped[80] ^= 0x40;
  mcap_write_file(path, flipped);
  EXPECT_THROW((void)mcap::read_file(path), InputError);
  flipped = whole;
  flipped[whole.size() - 40] ^= 0x01;
  mcap_write_file(path, flipped);
  EXPECT_THROW((void)mcap::read_file(path), InputError);
}

RobotModel mcap_test_model() {
  RobotModel m;
  m.name = "tiny";
  m.rate_hz = 100.0;
  m.joint_names = {"a", "b"};
  m.buses.push_back(BusModel{"bus", {0, 1}, {1, 2}});
  return m;
}

TEST(McapRecorder, ARecordingReplaysWithTheValuesTheCyclePushed) {
  const std::string path = ::testing::TempDir() + "mcap_recorder.mcap";
  const RobotModel model = mcap_test_model();
  {
    McapRecorder recorder(path, model);
    const std::size_t extra =
        recorder.add(RecordChannel{"attitude", "test.Attitude", {"roll", "pitch"}, true, 16});
    recorder.start();
    for (int i = 0; i < 50; ++i) {
      const double t = i * 0.01;
      const double cmd[] = {0.1 * i, -0.2 * i};
      const double meas[] = {0.1 * i - 0.001, -0.2 * i + 0.002};
      ASSERT_TRUE(recorder.push_joints(t, cmd, meas));
    }
    const double attitude[] = {0.2, static_cast<double>(recorder.device_index(0, 1)), 0.5, -0.25};
    ASSERT_TRUE(recorder.push(extra, attitude));
    ASSERT_TRUE(recorder.push_stop_request(0.3));
    recorder.finish();
    const std::pair<LogLevel, std::string> note{LogLevel::info, "run ended"};
    recorder.close({&note, 1});
    EXPECT_EQ(recorder.lost(), 0u);
    EXPECT_EQ(recorder.messages(), 50u * 2 + 1 + 2);
  }
  const TelemetryRecording rec = load_telemetry(path);
  ASSERT_EQ(rec.joints, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(rec.rows(), 50u);
  EXPECT_NEAR(rec.t[49], 0.49, 1e-9);
  EXPECT_DOUBLE_EQ(rec.cmd[2 * 49 + 1], -0.2 * 49);
  EXPECT_DOUBLE_EQ(rec.meas[2 * 49 + 0], 0.1 * 49 - 0.001);

  const mcap::ReadFile file = mcap::read_file(path);
  const mcap::ReadChannel* attitude = file.channel("/devices/bus/b/attitude");
  ASSERT_NE(attitude, nullptr);
  EXPECT_EQ(attitude->schema_name, "test.Attitude");
  std::vector<std::string> logs;
  std::string attitude_json;
  for (const auto& m : file.messages) {
    if (m.channel == file.channel("/events")->id) logs.push_back(m.data);
    if (m.channel == attitude->id) attitude_json = m.data;
  }
  EXPECT_NE(attitude_json.find(R"("device":"bus/b","roll":0.5,"pitch":-0.25)"), std::string::npos)
      << attitude_json;
  ASSERT_EQ(logs.size(), 2u);
  EXPECT_NE(logs[0].find(R"("level":2,"message":"stop requested)"), std::string::npos) << logs[0];
  EXPECT_NE(logs[1].find("run ended"), std::string::npos) << logs[1];
}

TEST(McapReplay, RefusesAnMcapWithoutJointStates) {
  const std::string path = ::testing::TempDir() + "mcap_other.mcap";
  {
    mcap::Writer w(path);
    w.add_channel(0, "/other", "json");
  }
  try {
    (void)load_telemetry(path);
    ADD_FAILURE() << "loaded an MCAP without joint states";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/joint_states"), std::string::npos) << e.what();
  }
}

// A recording is checked before its first bytes are peeked at for the MCAP
// magic: a FIFO (nothing writing to it) would block the open.
TEST(McapReplay, ARecordingThatIsAFifoIsRefusedWithoutWaiting) {
  const std::string path = ::testing::TempDir() + "replay_fifo.csv";
  ::unlink(path.c_str());
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  try {
    (void)load_telemetry(path);
    ADD_FAILURE() << "loaded a FIFO";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": is not a regular file (FIFO)");
  }
  ::unlink(path.c_str());
}

}  // namespace
}  // namespace animrt
