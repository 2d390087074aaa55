#pragma once
// Feetech SCS/STS serial-bus packet codec, used by both ends of the wire: the
// runtime's bus driver (instructions out, status in) and the simulated servo
// board (instructions in, status out).
//
// Packet: FF FF | ID | LEN | INST or ERROR | PARAMS... | CHECKSUM
// LEN counts the parameters plus 2 (instruction or error byte, checksum); the
// checksum is the one's complement of the low byte of ID + LEN + INST + PARAMS.
// No byte stuffing. A status packet has the servo's error byte where an
// instruction packet has its instruction; the two are told apart by who
// sends them, so a master skips the echo of its own instruction.
//
// Two-byte memory values: the STS series (magnetic encoder, 4096 steps per
// turn) stores them low byte first, the SCS series (potentiometer, 1024
// steps over about 300 degrees) high byte first. Signed values are
// sign-magnitude: a direction bit above the magnitude (bit 15 for STS
// positions and for speeds of both series, bit 10 for SCS loads and PWM;
// SCS positions are unsigned).

#include <cstddef>
#include <cstdint>
#include <span>

#include "animrt/bridge/serial_servo/rx_buffer.hpp"

namespace animrt::ft {

enum class Series : std::uint8_t { sts, scs };

inline constexpr std::uint8_t kBroadcastId = 0xFE;
inline constexpr int kMaxDeviceId = 253;
// LEN is one byte: 4 header/id/len bytes + at most 255.
inline constexpr std::size_t kMaxPacket = 4 + 255;

namespace inst {
inline constexpr std::uint8_t ping = 0x01;
inline constexpr std::uint8_t read = 0x02;
inline constexpr std::uint8_t write = 0x03;
inline constexpr std::uint8_t reg_write = 0x04;
inline constexpr std::uint8_t action = 0x05;
inline constexpr std::uint8_t reset = 0x06;
inline constexpr std::uint8_t sync_read = 0x82;  // STS series only
inline constexpr std::uint8_t sync_write = 0x83;
}  // namespace inst

// Status packet error byte (the same bits as the Servo Status register, 65).
namespace error_bit {
inline constexpr std::uint8_t voltage = 0x01;
inline constexpr std::uint8_t sensor = 0x02;
inline constexpr std::uint8_t temperature = 0x04;
inline constexpr std::uint8_t current = 0x08;
inline constexpr std::uint8_t angle = 0x10;
inline constexpr std::uint8_t overload = 0x20;
}  // namespace error_bit

// Memory table addresses common to STS3215 and SCS0009/SCS15 (their values'
// byte order differs, see above).
namespace reg {
inline constexpr std::uint8_t firmware_major = 0;        // 1
inline constexpr std::uint8_t model = 3;                 // 2 (servo main/sub version)
inline constexpr std::uint8_t id = 5;                    // 1
inline constexpr std::uint8_t baud_rate = 6;             // 1, 0 = 1 Mbaud .. 7 = 38400
inline constexpr std::uint8_t return_delay = 7;          // 1, unit 2 us
inline constexpr std::uint8_t status_return_level = 8;   // 1: 0 = only Read and Ping answer
inline constexpr std::uint8_t min_angle_limit = 9;       // 2, steps
inline constexpr std::uint8_t max_angle_limit = 11;      // 2, steps
inline constexpr std::uint8_t max_temperature = 13;      // 1, deg C
inline constexpr std::uint8_t unload_condition = 19;     // 1, error bits that cut torque
inline constexpr std::uint8_t position_offset = 31;      // 2, STS: sign bit 11
inline constexpr std::uint8_t operating_mode = 33;       // 1, STS: 0 = position
inline constexpr std::uint8_t torque_enable = 40;        // 1
inline constexpr std::uint8_t acceleration = 41;         // 1, STS only
inline constexpr std::uint8_t goal_position = 42;        // 2
inline constexpr std::uint8_t goal_time = 44;            // 2
inline constexpr std::uint8_t goal_speed = 46;           // 2
inline constexpr std::uint8_t sts_lock = 55;             // 1, EEPROM write lock (STS)
inline constexpr std::uint8_t scs_lock = 48;             // 1, EEPROM write lock (SCS)
inline constexpr std::uint8_t sts_torque_limit = 48;     // 2, STS: RAM, 0.1 % of full torque
inline constexpr std::uint8_t present_position = 56;     // 2
inline constexpr std::uint8_t present_speed = 58;        // 2
inline constexpr std::uint8_t present_load = 60;         // 2
inline constexpr std::uint8_t present_voltage = 62;      // 1, unit 0.1 V
inline constexpr std::uint8_t present_temperature = 63;  // 1
inline constexpr std::uint8_t registered = 64;           // 1, Reg Write pending
inline constexpr std::uint8_t servo_status = 65;         // 1, error bits
inline constexpr std::uint8_t moving = 66;               // 1
inline constexpr std::uint8_t table_size = 71;
}  // namespace reg

// STS Torque Limit at full torque (its power-up value: Max Torque, EEPROM 16,
// 1000 by default).
inline constexpr std::uint16_t kStsFullTorque = 1000;

// Steps per turn of the position sensor, and the range goal positions take
// in position mode.
inline constexpr double kStsStepsPerRev = 4096.0;
inline constexpr std::int32_t kStsMaxPosition = 4095;
// SCS: 1024 steps over about 300 degrees (0..1023).
inline constexpr double kScsStepsPerRev = 1024.0 * 360.0 / 300.0;
inline constexpr std::int32_t kScsMaxPosition = 1023;
// Direction bit of signed values: STS positions and both series' speeds
// (15); SCS loads and PWM (10).
inline constexpr int kStsSignBit = 15;
inline constexpr int kScsSignBit = 10;

std::uint8_t checksum(std::span<const std::uint8_t> id_to_last_param);

void put_u16(Series series, std::uint8_t* p, std::uint16_t v);
std::uint16_t get_u16(Series series, const std::uint8_t* p);

// Sign-magnitude with the direction bit `sign_bit`: |v| is clamped to the
// bits below it.
std::uint16_t encode_signed(std::int32_t v, int sign_bit);
std::int32_t decode_signed(std::uint16_t raw, int sign_bit);

// Encoders write one complete packet into `out` and return its length, or 0
// if `out` (or one packet) is too small. They never allocate.
std::size_t encode_packet(std::uint8_t id, std::uint8_t instruction,
                          std::span<const std::uint8_t> params, std::span<std::uint8_t> out);
std::size_t encode_ping(std::uint8_t id, std::span<std::uint8_t> out);
std::size_t encode_read(std::uint8_t id, std::uint8_t address, std::uint8_t length,
                        std::span<std::uint8_t> out);
std::size_t encode_write(std::uint8_t id, std::uint8_t address, std::span<const std::uint8_t> data,
                         std::span<std::uint8_t> out);
std::size_t encode_reg_write(std::uint8_t id, std::uint8_t address,
                             std::span<const std::uint8_t> data, std::span<std::uint8_t> out);
std::size_t encode_action(std::uint8_t id, std::span<std::uint8_t> out);
// Sync Read: broadcast; the servos in `ids` answer in that order.
std::size_t encode_sync_read(std::uint8_t address, std::uint8_t length,
                             std::span<const std::uint8_t> ids, std::span<std::uint8_t> out);
// Sync Write: `data` holds ids.size() blocks of `length` bytes, in id order.
std::size_t encode_sync_write(std::uint8_t address, std::uint8_t length,
                              std::span<const std::uint8_t> ids, std::span<const std::uint8_t> data,
                              std::span<std::uint8_t> out);
std::size_t encode_status(std::uint8_t id, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::span<std::uint8_t> out);

// A decoded packet; `params` and `raw` point into the Decoder's buffer, valid
// until the next call on it. `code` is the instruction (instruction packet) or
// the error byte (status packet).
struct Packet {
  std::uint8_t id = 0;
  std::uint8_t code = 0;
  std::span<const std::uint8_t> params;
  std::span<const std::uint8_t> raw;  // the whole packet as it arrived
};

enum class DecodeResult : std::uint8_t {
  packet,     // `out` holds the next packet
  need_more,  // no complete packet buffered yet
  bad_checksum,
  malformed,  // a header with an impossible id or length was dropped
};

// Streaming decoder with a fixed buffer: feed bytes as they arrive, then call
// next() until need_more. Bytes before a header are skipped and counted.
// No allocation.
class Decoder {
 public:
  void reset() { rx_.reset(); }
  // Appends bytes; returns how many fitted.
  std::size_t feed(std::span<const std::uint8_t> bytes) { return rx_.feed(bytes); }
  DecodeResult next(Packet& out);
  std::uint64_t stray_bytes() const { return rx_.stray(); }
  std::size_t buffered() const { return rx_.size(); }

 private:
  servo::RxBuffer<2 * kMaxPacket> rx_;
  std::uint8_t packet_[kMaxPacket]{};
};

}  // namespace animrt::ft
