#pragma once
// Dynamixel Protocol 2.0 as the serial-servo core sees it (servo_link.hpp):
// status packets carry instruction 0x55, an error byte whose bits 0-6 are
// an error number (a refusal) and bit 7 the hardware alert (the fault
// itself is in the Hardware Error Status register), data little-endian.

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/bridge/serial_servo/servo_link.hpp"

namespace animrt::dxl {

struct LinkCodec {
  using Packet = dxl::Packet;
  using Decoder = dxl::Decoder;
  static constexpr std::size_t kMaxPacket = dxl::kMaxPacket;
  static constexpr bool kFaultInErrorByte = false;
  static constexpr std::uint8_t kErrorNumberMask = 0x7F;

  servo::Frame next(Decoder& decoder, Packet& packet) const {
    switch (decoder.next(packet)) {
      case DecodeResult::packet:
        return servo::Frame::packet;
      case DecodeResult::need_more:
        return servo::Frame::need_more;
      case DecodeResult::bad_crc:
        return servo::Frame::bad_check;
      case DecodeResult::malformed:
        break;
    }
    return servo::Frame::malformed;
  }
  bool from_device(const Packet& packet, std::span<const std::uint8_t>) const {
    return packet.instruction == inst::status;
  }
  std::uint8_t id(const Packet& packet) const { return packet.id; }
  bool split(const Packet& packet, std::uint8_t& error, std::span<const std::uint8_t>& data) const {
    if (packet.params.empty()) return false;
    error = packet.params[0];
    data = packet.params.subspan(1);
    return true;
  }
  bool rejects(std::uint8_t error) const { return (error & kErrorNumberMask) != 0; }
  bool fault(std::uint8_t error) const { return (error & kAlertBit) != 0; }
  std::uint32_t value(std::span<const std::uint8_t> data) const {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < std::min<std::size_t>(4, data.size()); ++i) {
      v |= static_cast<std::uint32_t>(data[i]) << (8 * i);
    }
    return v;
  }
};

}  // namespace animrt::dxl
