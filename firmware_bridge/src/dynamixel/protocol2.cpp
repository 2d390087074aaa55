#include "animrt/bridge/dynamixel/protocol2.hpp"

#include <algorithm>
#include <array>
#include <cstring>

namespace animrt::dxl {
namespace {

constexpr std::uint8_t kHeader[4] = {0xFF, 0xFF, 0xFD, 0x00};
constexpr std::size_t kHeaderSize = 4;
constexpr std::size_t kPrefixSize = 7;  // header, id, length
constexpr std::size_t kCrcSize = 2;
// Smallest LEN: instruction + CRC. The largest keeps the packet within kMaxPacket.
constexpr std::size_t kMinLength = 3;
constexpr std::size_t kMaxLength = kMaxPacket - kPrefixSize;
constexpr std::uint8_t kReservedId1 = 0xFD;  // would read as part of a header
constexpr std::uint8_t kReservedId2 = 0xFF;

// ROBOTIS CRC-16: polynomial 0x8005, MSB first, initial value 0, no final xor.
// The table is the one printed in the e-manual's CRC page (entry 1 is 0x8005).
constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    auto crc = static_cast<std::uint16_t>(i << 8);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) ? static_cast<std::uint16_t>((crc << 1) ^ 0x8005)
                           : static_cast<std::uint16_t>(crc << 1);
    }
    table[i] = crc;
  }
  return table;
}
constexpr std::array<std::uint16_t, 256> kCrcTable = make_crc_table();
static_assert(kCrcTable[1] == 0x8005 && kCrcTable[255] == 0x0202);

// Writes one packet, stuffing INST..PARAMS on the fly, so composite encoders
// need no scratch buffer.
class PacketWriter {
 public:
  PacketWriter(std::span<std::uint8_t> out, std::uint8_t id, std::uint8_t instruction) : out_(out) {
    for (std::uint8_t b : kHeader) put(b);
    put(id);
    put(0);  // LEN, filled in by finish()
    put(0);
    body(instruction);
  }

  void body(std::uint8_t b) {
    put(b);
    if (b == 0xFD && ff_run_ >= 2) {
      put(0xFD);  // FF FF FD -> FF FF FD FD
      ff_run_ = 0;
    } else {
      ff_run_ = (b == 0xFF) ? ff_run_ + 1 : 0;
    }
  }
  void body_u16(std::uint16_t v) {
    body(static_cast<std::uint8_t>(v));
    body(static_cast<std::uint8_t>(v >> 8));
  }
  void body(std::span<const std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) body(b);
  }

  // Returns the packet's size, or 0 if it did not fit in `out` or kMaxPacket.
  std::size_t finish() {
    const std::size_t crc_at = pos_;
    put(0);
    put(0);
    if (overflow_ || pos_ > kMaxPacket) return 0;
    put_u16(out_.data() + 5, static_cast<std::uint16_t>(pos_ - kPrefixSize));
    put_u16(out_.data() + crc_at, crc16(out_.first(crc_at)));
    return pos_;
  }

 private:
  void put(std::uint8_t b) {
    if (pos_ < out_.size()) {
      out_[pos_] = b;
    } else {
      overflow_ = true;
    }
    ++pos_;
  }

  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  int ff_run_ = 0;
  bool overflow_ = false;
};

bool valid_id(std::uint8_t id) { return id != kReservedId1 && id != kReservedId2; }

}  // namespace

std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t accum) {
  for (std::uint8_t b : bytes) {
    const auto i = static_cast<std::uint8_t>((accum >> 8) ^ b);
    accum = static_cast<std::uint16_t>((accum << 8) ^ kCrcTable[i]);
  }
  return accum;
}

std::size_t encode_packet(std::uint8_t id, std::uint8_t instruction,
                          std::span<const std::uint8_t> params, std::span<std::uint8_t> out) {
  PacketWriter w(out, id, instruction);
  w.body(params);
  return w.finish();
}

std::size_t encode_ping(std::uint8_t id, std::span<std::uint8_t> out) {
  return encode_packet(id, inst::ping, {}, out);
}

std::size_t encode_read(std::uint8_t id, std::uint16_t address, std::uint16_t length,
                        std::span<std::uint8_t> out) {
  PacketWriter w(out, id, inst::read);
  w.body_u16(address);
  w.body_u16(length);
  return w.finish();
}

std::size_t encode_write(std::uint8_t id, std::uint16_t address, std::span<const std::uint8_t> data,
                         std::span<std::uint8_t> out) {
  PacketWriter w(out, id, inst::write);
  w.body_u16(address);
  w.body(data);
  return w.finish();
}

std::size_t encode_sync_read(std::uint16_t address, std::uint16_t length,
                             std::span<const std::uint8_t> ids, std::span<std::uint8_t> out) {
  PacketWriter w(out, kBroadcastId, inst::sync_read);
  w.body_u16(address);
  w.body_u16(length);
  w.body(ids);
  return w.finish();
}

std::size_t encode_sync_write(std::uint16_t address, std::uint16_t length,
                              std::span<const std::uint8_t> ids, std::span<const std::uint8_t> data,
                              std::span<std::uint8_t> out) {
  if (data.size() != ids.size() * length) return 0;
  PacketWriter w(out, kBroadcastId, inst::sync_write);
  w.body_u16(address);
  w.body_u16(length);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    w.body(ids[i]);
    w.body(data.subspan(i * length, length));
  }
  return w.finish();
}

std::size_t encode_fast_sync_read(std::uint16_t address, std::uint16_t length,
                                  std::span<const std::uint8_t> ids, std::span<std::uint8_t> out) {
  PacketWriter w(out, kBroadcastId, inst::fast_sync_read);
  w.body_u16(address);
  w.body_u16(length);
  w.body(ids);
  return w.finish();
}

namespace {
std::size_t encode_bulk(std::uint8_t instruction, std::span<const BulkReadEntry> entries,
                        std::span<std::uint8_t> out) {
  PacketWriter w(out, kBroadcastId, instruction);
  for (const BulkReadEntry& e : entries) {
    w.body(e.id);
    w.body_u16(e.address);
    w.body_u16(e.length);
  }
  return w.finish();
}
}  // namespace

std::size_t encode_bulk_read(std::span<const BulkReadEntry> entries, std::span<std::uint8_t> out) {
  return encode_bulk(inst::bulk_read, entries, out);
}

std::size_t encode_fast_bulk_read(std::span<const BulkReadEntry> entries,
                                  std::span<std::uint8_t> out) {
  return encode_bulk(inst::fast_bulk_read, entries, out);
}

std::size_t fast_status_size(std::size_t devices, std::size_t data_bytes) {
  return kFastHeaderSize + kFastSliceOverhead * devices + data_bytes;
}

FastStatusWriter::FastStatusWriter(std::span<std::uint8_t> out, std::size_t devices,
                                   std::size_t data_bytes)
    : out_(out), length_(fast_status_size(devices, data_bytes) - kPrefixSize) {}

void FastStatusWriter::header() {
  if (out_.size() < kFastHeaderSize) {
    overflow_ = true;
    return;
  }
  std::memcpy(out_.data(), kHeader, kHeaderSize);
  out_[4] = kBroadcastId;
  put_u16(out_.data() + 5, static_cast<std::uint16_t>(length_));
  out_[7] = inst::status;
  size_ = kFastHeaderSize;
}

bool FastStatusWriter::slice(std::uint8_t error, std::uint8_t id,
                             std::span<const std::uint8_t> data) {
  if (overflow_ || size_ == 0 || size_ + kFastSliceOverhead + data.size() > out_.size()) {
    overflow_ = true;
    return false;
  }
  std::uint8_t* p = out_.data() + size_;
  p[0] = error;
  p[1] = id;
  if (!data.empty()) std::memcpy(p + 2, data.data(), data.size());
  const std::size_t crc_at = size_ + 2 + data.size();
  put_u16(out_.data() + crc_at, crc16(out_.first(crc_at)));
  size_ = crc_at + kCrcSize;
  return true;
}

FastStatusReader::FastStatusReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {
  for (std::size_t i = 0; i + kFastHeaderSize <= bytes_.size(); ++i) {
    if (std::memcmp(bytes_.data() + i, kHeader, kHeaderSize) == 0 &&
        bytes_[i + 4] == kBroadcastId && bytes_[i + 7] == inst::status) {
      start_ = i;
      pos_ = i + kFastHeaderSize;
      crc_ = crc16(bytes_.subspan(i, kFastHeaderSize));
      return;
    }
  }
}

std::size_t FastStatusReader::announced_size() const {
  if (!has_header()) return 0;
  return kPrefixSize + get_u16(bytes_.data() + start_ + 5);
}

bool FastStatusReader::complete() const {
  return has_header() && bytes_.size() - start_ >= announced_size();
}

std::size_t FastStatusReader::after_header() const {
  return has_header() ? bytes_.size() - start_ - kFastHeaderSize : 0;
}

bool FastStatusReader::peek_id(std::uint8_t& id) const {
  if (!has_header() || stopped_ || pos_ + 2 > bytes_.size()) return false;
  id = bytes_[pos_ + 1];
  return true;
}

FastStatusReader::Step FastStatusReader::next(std::size_t data_length, FastSlice& out) {
  if (!has_header() || stopped_ || pos_ >= bytes_.size() || pos_ >= start_ + announced_size()) {
    return Step::end;
  }
  const std::size_t crc_at = pos_ + 2 + data_length;
  if (crc_at + kCrcSize > bytes_.size()) {
    stopped_ = true;
    return Step::short_;
  }
  const std::uint16_t crc = crc16(bytes_.subspan(pos_, crc_at - pos_), crc_);
  if (crc != get_u16(bytes_.data() + crc_at)) {
    stopped_ = true;
    return Step::bad_crc;
  }
  out.error = bytes_[pos_];
  out.id = bytes_[pos_ + 1];
  out.data = bytes_.subspan(pos_ + 2, data_length);
  // The running CRC continues over this slice's CRC bytes.
  crc_ = crc16(bytes_.subspan(crc_at, kCrcSize), crc);
  pos_ = crc_at + kCrcSize;
  return Step::slice;
}

std::size_t encode_status(std::uint8_t id, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::span<std::uint8_t> out) {
  PacketWriter w(out, id, inst::status);
  w.body(error);
  w.body(data);
  return w.finish();
}

DecodeResult Decoder::next(Packet& out) {
  // Skip to the first header; keep a partial header at the end of the buffer.
  std::size_t start = 0;
  std::size_t matched = 0;
  while (start + matched < rx_.size() && matched < kHeaderSize) {
    if (rx_[start + matched] == kHeader[matched]) {
      ++matched;
    } else {
      ++start;
      matched = 0;
    }
  }
  rx_.skip(start);
  if (rx_.size() < kPrefixSize) return DecodeResult::need_more;

  const std::uint8_t id = rx_[4];
  const std::size_t length = get_u16(rx_.data() + 5);
  if (!valid_id(id) || length < kMinLength || length > kMaxLength) {
    // Not a packet start after all: drop the header and search again, so a
    // real header right behind it is still found.
    rx_.drop_front(kHeaderSize);
    return DecodeResult::malformed;
  }
  const std::size_t total = kPrefixSize + length;
  if (rx_.size() < total) return DecodeResult::need_more;  // truncated so far

  const std::size_t crc_at = total - kCrcSize;
  if (crc16({rx_.data(), crc_at}) != get_u16(rx_.data() + crc_at)) {
    // Drop only the header: if LEN was corrupted, the packets it swallowed
    // are found on the next search.
    rx_.drop_front(kHeaderSize);
    return DecodeResult::bad_crc;
  }

  // Unstuff INST..PARAMS: FF FF FD FD -> FF FF FD. A lone FF FF FD inside a
  // packet is a protocol violation (it would read as a header).
  std::size_t n = 0;
  int ff_run = 0;
  bool bad_stuffing = false;
  for (std::size_t i = kPrefixSize; i < crc_at; ++i) {
    const std::uint8_t b = rx_[i];
    unstuffed_[n++] = b;
    if (b == 0xFD && ff_run >= 2) {
      if (i + 1 >= crc_at || rx_[i + 1] != 0xFD) {
        bad_stuffing = true;
        break;
      }
      ++i;  // skip the stuffed FD
      ff_run = 0;
    } else {
      ff_run = (b == 0xFF) ? ff_run + 1 : 0;
    }
  }
  const std::uint8_t instruction = unstuffed_[0];
  if (bad_stuffing || (instruction == inst::status && n < 2)) {
    rx_.drop_front(total);
    return DecodeResult::malformed;
  }
  rx_.drop_front(total);
  out.id = id;
  out.instruction = instruction;
  out.params = std::span<const std::uint8_t>(unstuffed_ + 1, n - 1);
  return DecodeResult::packet;
}

}  // namespace animrt::dxl
