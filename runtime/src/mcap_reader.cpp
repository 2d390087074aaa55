// Reading MCAP record by record (see mcap_reader.hpp).

#include "animrt/runtime/mcap_reader.hpp"

#include <zstd.h>

#include <cstring>
#include <string_view>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"

namespace animrt::mcap {
namespace {

constexpr std::uintmax_t kMaxMcapFileBytes = std::uintmax_t{1} << 30;
// A chunk is inflated whole: 64 MiB bounds what a header claiming more costs
// (writers close their chunks at a few MiB).
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 26;  // uncompressed

const char* mcap_record_name(std::uint8_t op) {
  static constexpr const char* kNames[] = {
      "record 0x00", "Header",        "Footer",          "Schema",
      "Channel",     "Message",       "Chunk",           "MessageIndex",
      "ChunkIndex",  "Attachment",    "AttachmentIndex", "Statistics",
      "Metadata",    "MetadataIndex", "SummaryOffset",   "DataEnd"};
  return op < std::size(kNames) ? kNames[op] : "unknown record";
}

class McapParser {
 public:
  McapParser(const std::string& name, const std::string& where) : name_(name), where_(where) {}

  [[noreturn]] void fail(std::uint64_t at, const std::string& message) const {
    throw InputError(Location{name_, 0, 0}, "",
                     "byte " + std::to_string(at) + where_ + ": " + message);
  }

  // A cursor over one record's content (or a chunk's records).
  struct Cursor {
    const McapParser& p;
    std::span<const std::uint8_t> b;
    std::uint64_t base;  // file offset of b[0] (in a chunk: of the chunk)
    std::size_t i = 0;
    const char* what;

    void need(std::size_t n) {
      if (b.size() - i < n) {
        p.fail(base + i, std::string(what) + " ends after " + std::to_string(b.size()) +
                             " bytes, in the middle of a field of " + std::to_string(n) + " bytes");
      }
    }
    std::uint64_t le(int n) {
      need(static_cast<std::size_t>(n));
      std::uint64_t v = 0;
      for (int k = 0; k < n; ++k) v |= std::uint64_t{b[i + static_cast<std::size_t>(k)]} << (8 * k);
      i += static_cast<std::size_t>(n);
      return v;
    }
    std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
    std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
    std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
    std::uint64_t u64() { return le(8); }
    std::span<const std::uint8_t> bytes(std::uint64_t n) {
      if (n > b.size() - i) need(b.size() - i + 1);
      const auto out = b.subspan(i, static_cast<std::size_t>(n));
      i += static_cast<std::size_t>(n);
      return out;
    }
    std::string str() {
      const auto s = bytes(u32());
      return std::string(s.begin(), s.end());
    }
    StringMap string_map() {
      Cursor m{p, bytes(u32()), base + i, 0, what};
      StringMap out;
      while (m.i < m.b.size()) {
        std::string k = m.str();
        out.emplace_back(std::move(k), m.str());
      }
      return out;
    }
    bool done() const { return i == b.size(); }
  };

  const std::string& name_;
  std::string where_;
};

struct McapState {
  std::map<std::uint16_t, std::pair<std::string, std::string>> schemas;  // name, encoding
  ReadFile out;
};

// One record of the data section (or of a chunk) into the state.
void take(const McapParser& p, std::uint8_t op, McapParser::Cursor c, McapState& s, bool in_chunk);

void read_mcap_records(const McapParser& p, McapParser::Cursor& all, McapState& s, bool in_chunk,
                       std::uint64_t* data_end_at) {
  while (!all.done()) {
    const std::uint64_t at = all.base + all.i;
    if (all.b.size() - all.i < 9) {
      p.fail(at, std::string("truncated: a record header needs 9 bytes, ") +
                     std::to_string(all.b.size() - all.i) + " remain" +
                     (in_chunk ? "" : " (a recording cut short?)"));
    }
    const std::uint8_t op = all.u8();
    const std::uint64_t length = all.u64();
    if (length > all.b.size() - all.i) {
      p.fail(at, std::string("truncated: the ") + mcap_record_name(op) + " record claims " +
                     std::to_string(length) + " bytes, " + std::to_string(all.b.size() - all.i) +
                     " remain" + (in_chunk ? "" : " (a recording cut short?)"));
    }
    McapParser::Cursor c{p, all.bytes(length), at + 9, 0, mcap_record_name(op)};
    if (!in_chunk && static_cast<Op>(op) == Op::data_end) {
      *data_end_at = at;
      return;
    }
    take(p, op, c, s, in_chunk);
  }
  if (!in_chunk) p.fail(all.base + all.i, "truncated: no DataEnd record (a recording cut short?)");
}

void take_mcap_channel(const McapParser& p, McapParser::Cursor& c, McapState& s) {
  ReadChannel ch;
  ch.id = c.u16();
  const std::uint16_t schema = c.u16();
  ch.topic = c.str();
  ch.message_encoding = c.str();
  (void)c.string_map();
  if (schema != 0) {
    const auto it = s.schemas.find(schema);
    if (it == s.schemas.end()) {
      p.fail(c.base, "channel " + ch.topic + " names schema " + std::to_string(schema) +
                         ", which no earlier Schema record defines");
    }
    ch.schema_name = it->second.first;
    ch.schema_encoding = it->second.second;
  }
  s.out.channels[ch.id] = std::move(ch);
}

void take_mcap_message(const McapParser& p, McapParser::Cursor& c, McapState& s) {
  ReadMessage m;
  m.channel = c.u16();
  m.sequence = c.u32();
  m.log_time = c.u64();
  (void)c.u64();
  const auto data = c.bytes(c.b.size() - c.i);
  m.data.assign(data.begin(), data.end());
  if (!s.out.channels.contains(m.channel)) {
    p.fail(c.base, "a message on channel " + std::to_string(m.channel) +
                       ", which no earlier Channel record defines");
  }
  s.out.messages.push_back(std::move(m));
}

// A chunk's records as they were before compression, checked against its
// header's size and CRC.
std::vector<std::uint8_t> inflate_mcap_chunk(const McapParser& p, McapParser::Cursor& c) {
  (void)c.u64();
  (void)c.u64();
  const std::uint64_t size = c.u64();
  const std::uint32_t crc = c.u32();
  const std::string compression = c.str();
  const auto records = c.bytes(c.u64());
  if (size > kMaxChunkBytes) {
    p.fail(c.base, "a chunk of " + std::to_string(size) + " bytes uncompressed is too large");
  }
  std::vector<std::uint8_t> plain;
  if (compression.empty()) {
    plain.assign(records.begin(), records.end());
  } else if (compression == "zstd") {
    plain.resize(static_cast<std::size_t>(size));
    const std::size_t n =
        ZSTD_decompress(plain.data(), plain.size(), records.data(), records.size());
    if (ZSTD_isError(n) || n != size) {
      p.fail(c.base, std::string("a zstd chunk does not inflate to its ") + std::to_string(size) +
                         " bytes" +
                         (ZSTD_isError(n) ? std::string(": ") + ZSTD_getErrorName(n) : ""));
    }
  } else {
    p.fail(c.base, "chunk compression \"" + compression + "\" is not supported (zstd or none)");
  }
  if (plain.size() != size) {
    p.fail(c.base, "a chunk holds " + std::to_string(plain.size()) + " bytes, its header says " +
                       std::to_string(size));
  }
  if (crc != 0 && crc32(plain) != crc) p.fail(c.base, "chunk CRC does not match its records");
  return plain;
}

void take(const McapParser& p, std::uint8_t op, McapParser::Cursor c, McapState& s, bool in_chunk) {
  switch (static_cast<Op>(op)) {
    case Op::schema: {
      const std::uint16_t id = c.u16();
      std::string name = c.str();
      s.schemas[id] = {std::move(name), c.str()};
      break;
    }
    case Op::channel:
      take_mcap_channel(p, c, s);
      break;
    case Op::message:
      take_mcap_message(p, c, s);
      break;
    case Op::chunk: {
      if (in_chunk) p.fail(c.base, "a Chunk inside a chunk");
      const std::vector<std::uint8_t> plain = inflate_mcap_chunk(p, c);
      McapParser inner(p.name_,
                       p.where_ + " (in the chunk at byte " + std::to_string(c.base - 9) + ")");
      McapParser::Cursor all{inner, plain, 0, 0, "chunk"};
      read_mcap_records(inner, all, s, true, nullptr);
      break;
    }
    case Op::metadata: {
      std::string name = c.str();
      s.out.metadata.emplace_back(std::move(name), c.string_map());
      break;
    }
    case Op::header:
    case Op::footer:
    case Op::data_end:
      p.fail(c.base - 9, std::string("a ") + mcap_record_name(op) + " record out of place");
    default:
      break;  // indexes, attachments, unknown records: skipped
  }
}

}  // namespace

const ReadChannel* ReadFile::channel(const std::string& topic) const {
  for (const auto& [id, ch] : channels) {
    if (ch.topic == topic) return &ch;
  }
  return nullptr;
}

bool has_magic(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= sizeof kMagic && std::memcmp(bytes.data(), kMagic, sizeof kMagic) == 0;
}

ReadFile read_bytes(std::span<const std::uint8_t> bytes, const std::string& name) {
  const McapParser p(name, "");
  if (!has_magic(bytes)) p.fail(0, "expected the MCAP magic (0x89 MCAP0 \\r\\n)");
  McapParser::Cursor all{p, bytes.subspan(sizeof kMagic), sizeof kMagic, 0, "file"};
  McapState s;
  // The Header first.
  if (all.b.size() < 9 || all.b[0] != static_cast<std::uint8_t>(Op::header)) {
    p.fail(sizeof kMagic, "expected the Header record after the magic");
  }
  (void)all.u8();
  const std::uint64_t header_length = all.u64();
  if (header_length > all.b.size() - all.i) {
    p.fail(sizeof kMagic, "truncated: the Header record claims " + std::to_string(header_length) +
                              " bytes, " + std::to_string(all.b.size() - all.i) + " remain");
  }
  (void)all.bytes(header_length);
  std::uint64_t data_end = 0;
  read_mcap_records(p, all, s, false, &data_end);
  // Data End, the summary and the footer.
  McapParser::Cursor de{p, bytes.subspan(static_cast<std::size_t>(data_end) + 9, 4), data_end + 9,
                        0, "DataEnd"};
  const std::uint32_t data_crc = de.u32();
  if (data_crc != 0 && crc32(bytes.first(static_cast<std::size_t>(data_end))) != data_crc) {
    p.fail(data_end, "data section CRC does not match its bytes");
  }
  const std::size_t tail = 9 + 8 + 8 + 4 + sizeof kMagic;
  if (bytes.size() < data_end + 13 + tail ||
      std::memcmp(bytes.data() + bytes.size() - sizeof kMagic, kMagic, sizeof kMagic) != 0) {
    p.fail(bytes.size(), "truncated: no Footer and closing magic (a recording cut short?)");
  }
  const std::size_t footer = bytes.size() - tail;
  McapParser::Cursor f{p, bytes.subspan(footer, tail - sizeof kMagic), footer, 0, "Footer"};
  if (f.u8() != static_cast<std::uint8_t>(Op::footer) || f.u64() != 20) {
    p.fail(footer, "expected the Footer record before the closing magic");
  }
  const std::uint64_t summary_start = f.u64();
  (void)f.u64();
  const std::uint32_t summary_crc = f.u32();
  if (summary_start != 0) {
    if (summary_start < data_end + 13 || summary_start > footer) {
      p.fail(footer, "the Footer's summary start " + std::to_string(summary_start) +
                         " is outside the file's summary");
    }
    const auto summary =
        bytes.subspan(static_cast<std::size_t>(summary_start),
                      footer + 1 + 8 + 8 + 8 - static_cast<std::size_t>(summary_start));
    if (summary_crc != 0 && crc32(summary) != summary_crc) {
      p.fail(summary_start, "summary CRC does not match its bytes");
    }
  }
  return std::move(s.out);
}

ReadFile read_file(const std::string& path) {
  const std::string text = read_input_file(path, kMaxMcapFileBytes);
  return read_bytes(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()),
                    path);
}

}  // namespace animrt::mcap
