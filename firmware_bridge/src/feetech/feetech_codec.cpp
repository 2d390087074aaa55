#include "animrt/bridge/feetech/feetech_codec.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace animrt::ft {
namespace {

constexpr std::size_t kPrefixSize = 4;  // FF FF ID LEN
constexpr std::size_t kMinLength = 2;   // instruction/error + checksum

// Writes one packet; composite encoders need no scratch buffer.
class PacketWriter {
 public:
  PacketWriter(std::span<std::uint8_t> out, std::uint8_t id, std::uint8_t code) : out_(out) {
    put(0xFF);
    put(0xFF);
    put(id);
    put(0);  // LEN, filled in by finish()
    put(code);
  }
  void put(std::uint8_t b) {
    if (pos_ < out_.size()) {
      out_[pos_] = b;
    } else {
      overflow_ = true;
    }
    ++pos_;
  }
  void put(std::span<const std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) put(b);
  }
  std::size_t finish() {
    const std::size_t sum_at = pos_;
    put(0);
    if (overflow_ || pos_ > kMaxPacket) return 0;
    out_[3] = static_cast<std::uint8_t>(pos_ - kPrefixSize);
    out_[sum_at] = checksum(out_.subspan(2, sum_at - 2));
    return pos_;
  }

 private:
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool overflow_ = false;
};

}  // namespace

std::uint8_t checksum(std::span<const std::uint8_t> id_to_last_param) {
  unsigned sum = 0;
  for (std::uint8_t b : id_to_last_param) sum += b;
  return static_cast<std::uint8_t>(~sum);
}

void put_u16(Series series, std::uint8_t* p, std::uint16_t v) {
  const auto lo = static_cast<std::uint8_t>(v);
  const auto hi = static_cast<std::uint8_t>(v >> 8);
  p[0] = series == Series::sts ? lo : hi;
  p[1] = series == Series::sts ? hi : lo;
}

std::uint16_t get_u16(Series series, const std::uint8_t* p) {
  return series == Series::sts ? static_cast<std::uint16_t>(p[0] | (p[1] << 8))
                               : static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

std::uint16_t encode_signed(std::int32_t v, int sign_bit) {
  const std::int32_t max = (1 << sign_bit) - 1;
  const std::int32_t magnitude = std::min(std::abs(std::max(v, -max)), max);
  return static_cast<std::uint16_t>(v < 0 ? (magnitude | (1 << sign_bit)) : magnitude);
}

std::int32_t decode_signed(std::uint16_t raw, int sign_bit) {
  const std::int32_t magnitude = raw & ((1 << sign_bit) - 1);
  return (raw & (1 << sign_bit)) != 0 ? -magnitude : magnitude;
}

std::size_t encode_packet(std::uint8_t id, std::uint8_t instruction,
                          std::span<const std::uint8_t> params, std::span<std::uint8_t> out) {
  PacketWriter w(out, id, instruction);
  w.put(params);
  return w.finish();
}

std::size_t encode_ping(std::uint8_t id, std::span<std::uint8_t> out) {
  return encode_packet(id, inst::ping, {}, out);
}

std::size_t encode_read(std::uint8_t id, std::uint8_t address, std::uint8_t length,
                        std::span<std::uint8_t> out) {
  const std::uint8_t params[2] = {address, length};
  return encode_packet(id, inst::read, params, out);
}

std::size_t encode_write(std::uint8_t id, std::uint8_t address, std::span<const std::uint8_t> data,
                         std::span<std::uint8_t> out) {
  PacketWriter w(out, id, inst::write);
  w.put(address);
  w.put(data);
  return w.finish();
}

std::size_t encode_reg_write(std::uint8_t id, std::uint8_t address,
                             std::span<const std::uint8_t> data, std::span<std::uint8_t> out) {
  PacketWriter w(out, id, inst::reg_write);
  w.put(address);
  w.put(data);
  return w.finish();
}

std::size_t encode_action(std::uint8_t id, std::span<std::uint8_t> out) {
  return encode_packet(id, inst::action, {}, out);
}

std::size_t encode_sync_read(std::uint8_t address, std::uint8_t length,
                             std::span<const std::uint8_t> ids, std::span<std::uint8_t> out) {
  PacketWriter w(out, kBroadcastId, inst::sync_read);
  w.put(address);
  w.put(length);
  w.put(ids);
  return w.finish();
}

std::size_t encode_sync_write(std::uint8_t address, std::uint8_t length,
                              std::span<const std::uint8_t> ids, std::span<const std::uint8_t> data,
                              std::span<std::uint8_t> out) {
  if (data.size() != ids.size() * length) return 0;
  PacketWriter w(out, kBroadcastId, inst::sync_write);
  w.put(address);
  w.put(length);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    w.put(ids[i]);
    w.put(data.subspan(i * length, length));
  }
  return w.finish();
}

std::size_t encode_status(std::uint8_t id, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::span<std::uint8_t> out) {
  return encode_packet(id, error, data, out);
}

DecodeResult Decoder::next(Packet& out) {
  // Skip to the first FF FF that is not followed by another FF (a run of FF
  // is idle line or junk; the last two of the run are the header).
  std::size_t start = 0;
  while (start < rx_.size()) {
    if (rx_[start] != 0xFF) {
      ++start;
      continue;
    }
    if (start + 1 >= rx_.size()) break;  // a lone FF at the end: maybe half a header
    if (rx_[start + 1] != 0xFF) {
      start += 2;
      continue;
    }
    if (start + 2 < rx_.size() && rx_[start + 2] == 0xFF) {
      ++start;
      continue;
    }
    break;
  }
  rx_.skip(start);
  if (rx_.size() < kPrefixSize) return DecodeResult::need_more;

  const std::size_t length = rx_[3];
  if (length < kMinLength) {
    rx_.drop_front(2);  // not a packet start after all; search on behind it
    return DecodeResult::malformed;
  }
  const std::size_t total = kPrefixSize + length;
  if (rx_.size() < total) return DecodeResult::need_more;
  if (checksum({rx_.data() + 2, total - 3}) != rx_[total - 1]) {
    // Drop only the header: if LEN was damaged, the packets it swallowed are
    // found on the next search.
    rx_.drop_front(2);
    return DecodeResult::bad_checksum;
  }
  std::memcpy(packet_, rx_.data(), total);
  rx_.drop_front(total);
  out.id = packet_[2];
  out.code = packet_[4];
  out.params = std::span<const std::uint8_t>(packet_ + 5, total - 6);
  out.raw = std::span<const std::uint8_t>(packet_, total);
  return DecodeResult::packet;
}

}  // namespace animrt::ft
