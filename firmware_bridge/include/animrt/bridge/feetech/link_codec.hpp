#pragma once
// Feetech SCS/STS as the serial-servo core sees it (servo_link.hpp): a
// status packet has the servo's fault bits where an instruction has its
// instruction (so the master skips the echo of its own packet by its
// bytes), nothing refuses an instruction, and two-byte values are in the
// series' byte order.

#include <cstring>

#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/bridge/serial_servo/servo_link.hpp"

namespace animrt::ft {

struct LinkCodec {
  using Packet = ft::Packet;
  using Decoder = ft::Decoder;
  static constexpr std::size_t kMaxPacket = ft::kMaxPacket;
  static constexpr bool kFaultInErrorByte = true;

  Series series = Series::sts;

  servo::Frame next(Decoder& decoder, Packet& packet) const {
    switch (decoder.next(packet)) {
      case DecodeResult::packet:
        return servo::Frame::packet;
      case DecodeResult::need_more:
        return servo::Frame::need_more;
      case DecodeResult::bad_checksum:
        return servo::Frame::bad_check;
      case DecodeResult::malformed:
        break;
    }
    return servo::Frame::malformed;
  }
  bool from_device(const Packet& packet, std::span<const std::uint8_t> sent) const {
    // Nothing comes from the broadcast id (an echo of an earlier broadcast).
    if (packet.id == kBroadcastId) return false;
    return !(packet.raw.size() == sent.size() &&
             std::memcmp(packet.raw.data(), sent.data(), sent.size()) == 0);
  }
  std::uint8_t id(const Packet& packet) const { return packet.id; }
  bool split(const Packet& packet, std::uint8_t& error, std::span<const std::uint8_t>& data) const {
    error = packet.code;
    data = packet.params;
    return true;
  }
  bool rejects(std::uint8_t) const { return false; }
  bool fault(std::uint8_t error) const { return error != 0; }
  std::uint32_t value(std::span<const std::uint8_t> data) const {
    if (data.size() >= 2) return get_u16(series, data.data());
    return data.empty() ? 0 : data[0];
  }
};

}  // namespace animrt::ft
