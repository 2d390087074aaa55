#pragma once
// An MCAP file (https://mcap.dev/spec, major version 0) written record by
// record: the leading magic and Header; Schema, Channel and Message records
// gathered into Chunks (zstd-compressed, or stored), each followed by its
// Message Index records; Metadata; then Data End, a Summary section
// (schemas, channels, Statistics, Chunk and Metadata Indexes), its Summary
// Offsets, the Footer and the trailing magic. Every CRC the format has is
// filled in: each chunk's, the data section's and the summary's.
//
// Not for the real-time cycle: it allocates and writes to a file. A run's
// recording feeds it from a writer thread (mcap_recorder.hpp).

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace animrt::mcap {

// CRC-32 (ISO-HDLC: zlib's, the one MCAP specifies), continued from `crc`
// (0 to start).
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0);

inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum class Op : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

enum class Compression { none, zstd };

struct WriterOptions {
  Compression compression = Compression::zstd;
  std::size_t chunk_bytes = 256 * 1024;  // a chunk closes once its records reach this
  int zstd_level = 3;
  std::string profile;  // Header.profile: "" (no ROS profile)
  std::string library = "animrt";
};

using StringMap = std::vector<std::pair<std::string, std::string>>;

class Writer {
 public:
  // Creates the file and writes the magic and Header; throws
  // std::runtime_error naming the file when it cannot be created.
  explicit Writer(const std::string& path, WriterOptions options = {});
  ~Writer();  // close()s
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Ids count from 1 (0 means "no schema" in a Channel).
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic,
                            std::string_view message_encoding, const StringMap& metadata = {});
  void add_metadata(std::string_view name, const StringMap& entries);
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
             std::uint64_t publish_time, std::string_view data);
  // Closes the open chunk and writes the summary, footer and magic. The file
  // is complete after it; later calls do nothing.
  void close();

  std::uint64_t messages() const { return messages_; }  // given to write()
  // Messages whose chunk did not reach the file (a full disk, an I/O error).
  std::uint64_t lost() const { return lost_; }
  int error() const { return error_; }             // errno of the first failed write, 0 if none
  std::uint64_t bytes() const { return offset_; }  // written to the file so far

 private:
  struct Schema {
    std::uint16_t id;
    std::string name, encoding, data;
  };
  struct Channel {
    std::uint16_t id, schema_id;
    std::string topic, encoding;
    StringMap metadata;
  };
  struct ChunkIndex {
    std::uint64_t start, end, offset, length, index_length, compressed, uncompressed;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
    bool zstd;
  };
  struct MetadataIndex {
    std::uint64_t offset, length;
    std::string name;
  };

  void flush_chunk();
  // Appends bytes to the file; data section bytes go into its CRC.
  void emit(std::span<const std::uint8_t> bytes, bool data_section);

  WriterOptions options_;
  int fd_ = -1;
  bool closed_ = false;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  int error_ = 0;
  void* zstd_ = nullptr;  // ZSTD_CCtx

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<MetadataIndex> metadata_indexes_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t messages_ = 0, lost_ = 0;
  std::uint64_t start_time_ = 0, end_time_ = 0;

  // The open chunk: its records, times and per-channel message index.
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0, chunk_messages_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::vector<std::uint8_t> compressed_, scratch_;
};

}  // namespace animrt::mcap
