#pragma once
// Dynamixel Protocol 2.0 packet codec, used by both ends of the wire: the
// runtime's bus driver (instructions out, status in) and the simulated servo
// firmware (instructions in, status out).
//
// Packet: FF FF FD 00 | ID | LEN_L LEN_H | INST | PARAMS... | CRC_L CRC_H
// LEN counts INST + PARAMS + CRC after byte stuffing; the CRC (poly 0x8005)
// covers everything from the first FF up to the last parameter, stuffed.
// Stuffing: inside INST..PARAMS, every FF FF FD gets an extra FD appended.

#include <cstddef>
#include <cstdint>
#include <span>

namespace animrt::dxl {

inline constexpr std::uint8_t kBroadcastId = 0xFE;
inline constexpr std::size_t kMaxPacket = 1024;  // bytes on the wire, stuffed

namespace inst {
inline constexpr std::uint8_t ping = 0x01;
inline constexpr std::uint8_t read = 0x02;
inline constexpr std::uint8_t write = 0x03;
inline constexpr std::uint8_t reg_write = 0x04;
inline constexpr std::uint8_t action = 0x05;
inline constexpr std::uint8_t factory_reset = 0x06;
inline constexpr std::uint8_t reboot = 0x08;
inline constexpr std::uint8_t clear = 0x10;
inline constexpr std::uint8_t status = 0x55;
inline constexpr std::uint8_t sync_read = 0x82;
inline constexpr std::uint8_t sync_write = 0x83;
inline constexpr std::uint8_t bulk_read = 0x92;
inline constexpr std::uint8_t bulk_write = 0x93;
}  // namespace inst

// Status packet error byte: bit 7 is the hardware alert, bits 0-6 the error number.
inline constexpr std::uint8_t kAlertBit = 0x80;
enum class StatusError : std::uint8_t {
  none = 0,
  result_fail = 1,
  instruction = 2,
  crc = 3,
  data_range = 4,
  data_length = 5,
  data_limit = 6,
  access = 7,
};

// X-series control table (the addresses the runtime and simulator use).
namespace xreg {
inline constexpr std::uint16_t model_number = 0;          // 2 bytes
inline constexpr std::uint16_t firmware_version = 6;      // 1
inline constexpr std::uint16_t id = 7;                    // 1
inline constexpr std::uint16_t baud_rate = 8;             // 1
inline constexpr std::uint16_t return_delay_time = 9;     // 1, unit 2 us
inline constexpr std::uint16_t operating_mode = 11;       // 1, 3 = position
inline constexpr std::uint16_t velocity_limit = 44;       // 4, unit 0.229 rpm
inline constexpr std::uint16_t max_position_limit = 48;   // 4
inline constexpr std::uint16_t min_position_limit = 52;   // 4
inline constexpr std::uint16_t torque_enable = 64;        // 1
inline constexpr std::uint16_t led = 65;                  // 1
inline constexpr std::uint16_t status_return_level = 68;  // 1
inline constexpr std::uint16_t hardware_error_status = 70;  // 1
inline constexpr std::uint16_t goal_position = 116;       // 4
inline constexpr std::uint16_t moving = 122;              // 1
inline constexpr std::uint16_t present_velocity = 128;    // 4
inline constexpr std::uint16_t present_position = 132;    // 4
inline constexpr std::uint16_t present_temperature = 146;  // 1
inline constexpr std::uint16_t table_size = 147;
}  // namespace xreg

std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t accum = 0);

// Little-endian helpers.
inline void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
inline std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// Encoders write one complete, stuffed packet into `out` and return its
// length, or 0 if `out` is too small. They never allocate.
std::size_t encode_packet(std::uint8_t id, std::uint8_t instruction,
                          std::span<const std::uint8_t> params, std::span<std::uint8_t> out);
std::size_t encode_ping(std::uint8_t id, std::span<std::uint8_t> out);
std::size_t encode_read(std::uint8_t id, std::uint16_t address, std::uint16_t length,
                        std::span<std::uint8_t> out);
std::size_t encode_write(std::uint8_t id, std::uint16_t address,
                         std::span<const std::uint8_t> data, std::span<std::uint8_t> out);
// Sync Read: broadcast; the devices in `ids` answer in that order.
std::size_t encode_sync_read(std::uint16_t address, std::uint16_t length,
                             std::span<const std::uint8_t> ids, std::span<std::uint8_t> out);
// Sync Write: `data` holds ids.size() blocks of `length` bytes, in id order.
std::size_t encode_sync_write(std::uint16_t address, std::uint16_t length,
                              std::span<const std::uint8_t> ids,
                              std::span<const std::uint8_t> data, std::span<std::uint8_t> out);
// Status packet: error byte then data.
std::size_t encode_status(std::uint8_t id, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::span<std::uint8_t> out);

// A decoded packet. `params` is unstuffed and points into the Decoder's
// buffer, valid until the next call on that Decoder. For a status packet
// params[0] is the error byte and the data follows.
struct Packet {
  std::uint8_t id = 0;
  std::uint8_t instruction = 0;
  std::span<const std::uint8_t> params;
};

enum class DecodeResult : std::uint8_t {
  packet,     // `out` holds the next packet
  need_more,  // no complete packet buffered yet
  bad_crc,    // a complete packet with a wrong CRC was dropped
  malformed,  // a header with an impossible length (or bad stuffing) was dropped
};

// Streaming decoder with a fixed buffer: feed bytes as they arrive, then call
// next() until need_more. Bytes before a header are skipped and counted.
// No allocation after construction.
class Decoder {
 public:
  Decoder() = default;
  void reset();
  // Appends bytes; returns how many fitted (the rest must be fed again later).
  std::size_t feed(std::span<const std::uint8_t> bytes);
  DecodeResult next(Packet& out);
  std::uint64_t stray_bytes() const { return stray_bytes_; }
  std::size_t buffered() const { return size_; }

 private:
  void drop_front(std::size_t n);
  std::uint8_t buffer_[2 * kMaxPacket]{};
  std::uint8_t unstuffed_[kMaxPacket]{};
  std::size_t size_ = 0;
  std::uint64_t stray_bytes_ = 0;
};

}  // namespace animrt::dxl
