#pragma once
// Reads an MCAP file whole, in file order (the data section, chunks
// decompressed), checking what the format lets a reader check: the magic at
// both ends, every record's length, each chunk's CRC, the data section's and
// the summary's CRCs. Any file that is not whole and well formed (a
// recording cut short, a flipped byte) is refused with one InputError that
// names the file, the record and the byte offset.

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "animrt/runtime/mcap_writer.hpp"

namespace animrt::mcap {

struct ReadChannel {
  std::uint16_t id = 0;
  std::string topic, message_encoding, schema_name, schema_encoding;
};

struct ReadMessage {
  std::uint16_t channel = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::string data;
};

struct ReadFile {
  std::map<std::uint16_t, ReadChannel> channels;
  std::vector<ReadMessage> messages;  // in file order
  std::vector<std::pair<std::string, StringMap>> metadata;
  const ReadChannel* channel(const std::string& topic) const;
};

// `name` is the file the bytes came from, for messages.
ReadFile read_bytes(std::span<const std::uint8_t> bytes, const std::string& name);
ReadFile read_file(const std::string& path);
// Whether the bytes start with the MCAP magic.
bool has_magic(std::span<const std::uint8_t> bytes);

}  // namespace animrt::mcap
