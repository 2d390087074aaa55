// MCAP records laid out as the specification gives them (see mcap_writer.hpp):
// little-endian integers, strings and byte arrays prefixed by a uint32
// length, maps and arrays by their uint32 length in bytes, and every record
// as opcode, uint64 content length, content.

#include "animrt/runtime/mcap_writer.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zstd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "animrt/core/input_file.hpp"

namespace animrt::mcap {
namespace {

constexpr std::array<std::uint32_t, 256> make_mcap_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}
constexpr auto kMcapCrcTable = make_mcap_crc_table();

// A record's content, appended field by field.
class RecordOut {
 public:
  explicit RecordOut(std::vector<std::uint8_t>& bytes) : b_(bytes) {}
  void u8(std::uint8_t v) { b_.push_back(v); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void raw(std::string_view s) { b_.insert(b_.end(), s.begin(), s.end()); }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s);
  }
  // Opens a record; end_record() fills its length.
  std::size_t record(Op op) {
    u8(static_cast<std::uint8_t>(op));
    u64(0);
    return b_.size();
  }
  void end_record(std::size_t content) { patch(content - 8, b_.size() - content, 8); }
  // Opens a uint32 byte-length prefix (a map or an array); end_prefix() fills it.
  std::size_t prefix() {
    u32(0);
    return b_.size();
  }
  void end_prefix(std::size_t at) { patch(at - 4, b_.size() - at, 4); }
  void string_map(const StringMap& m) {
    const std::size_t at = prefix();
    for (const auto& [k, v] : m) {
      str(k);
      str(v);
    }
    end_prefix(at);
  }
  std::size_t size() const { return b_.size(); }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void patch(std::size_t at, std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i)
      b_[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  std::vector<std::uint8_t>& b_;
};

// The Summary section's records, group by group. The Writer's record lists
// are passed as they are (their types are its own).
void put_schema_records(RecordOut& out, const auto& schemas) {
  for (const auto& s : schemas) {
    const std::size_t rec = out.record(Op::schema);
    out.u16(s.id);
    out.str(s.name);
    out.str(s.encoding);
    out.str(s.data);
    out.end_record(rec);
  }
}

void put_channel_records(RecordOut& out, const auto& channels) {
  for (const auto& c : channels) {
    const std::size_t rec = out.record(Op::channel);
    out.u16(c.id);
    out.u16(c.schema_id);
    out.str(c.topic);
    out.str(c.encoding);
    out.string_map(c.metadata);
    out.end_record(rec);
  }
}

void put_chunk_index_records(RecordOut& out, const auto& chunk_indexes) {
  for (const auto& c : chunk_indexes) {
    const std::size_t rec = out.record(Op::chunk_index);
    out.u64(c.start);
    out.u64(c.end);
    out.u64(c.offset);
    out.u64(c.length);
    const std::size_t at = out.prefix();
    for (const auto& [channel, where] : c.index_offsets) {
      out.u16(channel);
      out.u64(where);
    }
    out.end_prefix(at);
    out.u64(c.index_length);
    out.str(c.zstd ? "zstd" : "");
    out.u64(c.compressed);
    out.u64(c.uncompressed);
    out.end_record(rec);
  }
}

void put_metadata_index_records(RecordOut& out, const auto& metadata_indexes) {
  for (const auto& m : metadata_indexes) {
    const std::size_t rec = out.record(Op::metadata_index);
    out.u64(m.offset);
    out.u64(m.length);
    out.str(m.name);
    out.end_record(rec);
  }
}

// A group of Summary records, found again by its Summary Offset.
struct SummaryGroup {
  Op op;
  std::uint64_t start, length;
};

// The Summary Offsets, the Footer and the closing magic, after the summary
// in `bytes`, which begins at `summary_start` in the file.
void put_summary_offsets_and_footer(std::vector<std::uint8_t>& bytes,
                                    const std::vector<SummaryGroup>& groups,
                                    std::uint64_t summary_start) {
  RecordOut out(bytes);
  const std::uint64_t offsets_start = summary_start + out.size();
  for (const SummaryGroup& g : groups) {
    const std::size_t rec = out.record(Op::summary_offset);
    out.u8(static_cast<std::uint8_t>(g.op));
    out.u64(g.start);
    out.u64(g.length);
    out.end_record(rec);
  }
  // The footer's length goes in before its CRC, which covers it.
  out.u8(static_cast<std::uint8_t>(Op::footer));
  out.u64(8 + 8 + 4);
  out.u64(summary_start);
  out.u64(groups.empty() ? 0 : offsets_start);
  out.u32(crc32(bytes));  // the summary up to and including summary_offset_start
  out.raw(std::string_view(reinterpret_cast<const char*>(kMagic), sizeof kMagic));
}

}  // namespace

std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) {
  crc = ~crc;
  for (const std::uint8_t b : bytes) crc = kMcapCrcTable[(crc ^ b) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

Writer::Writer(const std::string& path, WriterOptions options) : options_(std::move(options)) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    throw std::runtime_error("cannot write MCAP file " + path + ": " + std::strerror(errno));
  }
  if (options_.compression == Compression::zstd) zstd_ = ZSTD_createCCtx();
  std::vector<std::uint8_t> bytes(std::begin(kMagic), std::end(kMagic));
  RecordOut out(bytes);
  const std::size_t rec = out.record(Op::header);
  out.str(options_.profile);
  out.str(options_.library);
  out.end_record(rec);
  emit(bytes, true);
}

Writer::~Writer() {
  close();
  if (zstd_) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_));
  if (fd_ >= 0) ::close(fd_);
}

std::uint16_t Writer::add_schema(std::string_view name, std::string_view encoding,
                                 std::string_view data) {
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back(Schema{id, std::string(name), std::string(encoding), std::string(data)});
  RecordOut out(chunk_);
  const std::size_t rec = out.record(Op::schema);
  out.u16(id);
  out.str(name);
  out.str(encoding);
  out.str(data);
  out.end_record(rec);
  return id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, std::string_view topic,
                                  std::string_view message_encoding, const StringMap& metadata) {
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back(
      Channel{id, schema_id, std::string(topic), std::string(message_encoding), metadata});
  RecordOut out(chunk_);
  const std::size_t rec = out.record(Op::channel);
  out.u16(id);
  out.u16(schema_id);
  out.str(topic);
  out.str(message_encoding);
  out.string_map(metadata);
  out.end_record(rec);
  return id;
}

void Writer::add_metadata(std::string_view name, const StringMap& entries) {
  // Metadata records stay outside chunks: the open chunk goes first.
  if (chunk_messages_ > 0) flush_chunk();
  scratch_.clear();
  RecordOut out(scratch_);
  const std::size_t rec = out.record(Op::metadata);
  out.str(name);
  out.string_map(entries);
  out.end_record(rec);
  metadata_indexes_.push_back(MetadataIndex{offset_, scratch_.size(), std::string(name)});
  emit(scratch_, true);
}

void Writer::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                   std::uint64_t publish_time, std::string_view data) {
  if (closed_) return;
  if (chunk_messages_ == 0 || log_time < chunk_start_) chunk_start_ = log_time;
  if (chunk_messages_ == 0 || log_time > chunk_end_) chunk_end_ = log_time;
  if (messages_ == 0 || log_time < start_time_) start_time_ = log_time;
  if (messages_ == 0 || log_time > end_time_) end_time_ = log_time;
  chunk_index_[channel_id].emplace_back(log_time, chunk_.size());
  RecordOut out(chunk_);
  const std::size_t rec = out.record(Op::message);
  out.u16(channel_id);
  out.u32(sequence);
  out.u64(log_time);
  out.u64(publish_time);
  out.raw(data);
  out.end_record(rec);
  ++messages_;
  ++chunk_messages_;
  ++channel_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_bytes) flush_chunk();
}

void Writer::flush_chunk() {
  if (chunk_.empty()) return;
  std::span<const std::uint8_t> records = chunk_;
  std::string_view compression;
  if (zstd_) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n =
        ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_), compressed_.data(), compressed_.size(),
                          chunk_.data(), chunk_.size(), options_.zstd_level);
    if (!ZSTD_isError(n)) {
      records = std::span<const std::uint8_t>(compressed_.data(), n);
      compression = "zstd";
    }
  }
  ChunkIndex index{chunk_start_, chunk_end_,          offset_, 0, 0, records.size(), chunk_.size(),
                   {},           !compression.empty()};
  scratch_.clear();
  RecordOut out(scratch_);
  const std::size_t rec = out.record(Op::chunk);
  out.u64(chunk_start_);
  out.u64(chunk_end_);
  out.u64(chunk_.size());
  out.u32(crc32(chunk_));
  out.str(compression);
  out.u64(records.size());
  scratch_.insert(scratch_.end(), records.begin(), records.end());
  out.end_record(rec);
  index.length = scratch_.size();
  // Message Index records follow the chunk, one per channel it holds.
  for (const auto& [channel, entries] : chunk_index_) {
    index.index_offsets[channel] = offset_ + scratch_.size();
    const std::size_t mi = out.record(Op::message_index);
    out.u16(channel);
    const std::size_t at = out.prefix();
    for (const auto& [time, where] : entries) {
      out.u64(time);
      out.u64(where);
    }
    out.end_prefix(at);
    out.end_record(mi);
  }
  index.index_length = scratch_.size() - index.length;
  emit(scratch_, true);
  if (error_ != 0) {
    lost_ += chunk_messages_;
  } else {
    chunk_indexes_.push_back(std::move(index));
  }
  chunk_.clear();
  chunk_index_.clear();
  chunk_messages_ = 0;
}

void Writer::emit(std::span<const std::uint8_t> bytes, bool data_section) {
  if (data_section) data_crc_ = crc32(bytes, data_crc_);
  if (error_ != 0) return;  // the file is cut short already: nothing after it is readable
  std::size_t done = 0;
  error_ = write_all(fd_, bytes.data(), bytes.size(), &done);
  offset_ += done;
}

void Writer::close() {
  if (closed_) return;
  flush_chunk();
  closed_ = true;
  std::vector<std::uint8_t> bytes;
  RecordOut out(bytes);
  const std::size_t rec = out.record(Op::data_end);
  out.u32(data_crc_);
  out.end_record(rec);
  emit(bytes, false);

  // The summary: groups of records, each found again by a Summary Offset.
  const std::uint64_t summary_start = offset_;
  bytes.clear();
  std::vector<SummaryGroup> groups;
  const auto group = [&](Op op, const auto& put) {
    const std::size_t from = out.size();
    put();
    if (out.size() > from) {
      groups.push_back(SummaryGroup{op, summary_start + from, out.size() - from});
    }
  };
  group(Op::schema, [&] { put_schema_records(out, schemas_); });
  group(Op::channel, [&] { put_channel_records(out, channels_); });
  group(Op::statistics, [&] {
    const std::size_t stats = out.record(Op::statistics);
    const std::uint64_t written = messages_ - lost_;
    out.u64(written);
    out.u16(static_cast<std::uint16_t>(schemas_.size()));
    out.u32(static_cast<std::uint32_t>(channels_.size()));
    out.u32(0);  // attachments
    out.u32(static_cast<std::uint32_t>(metadata_indexes_.size()));
    out.u32(static_cast<std::uint32_t>(chunk_indexes_.size()));
    out.u64(written ? start_time_ : 0);
    out.u64(written ? end_time_ : 0);
    const std::size_t at = out.prefix();
    for (const auto& [channel, count] : channel_counts_) {
      out.u16(channel);
      out.u64(count);
    }
    out.end_prefix(at);
    out.end_record(stats);
  });
  group(Op::chunk_index, [&] { put_chunk_index_records(out, chunk_indexes_); });
  group(Op::metadata_index, [&] { put_metadata_index_records(out, metadata_indexes_); });
  put_summary_offsets_and_footer(bytes, groups, summary_start);
  emit(bytes, false);
}

}  // namespace animrt::mcap
