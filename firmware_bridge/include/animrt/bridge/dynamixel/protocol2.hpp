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

#include "animrt/bridge/serial_servo/rx_buffer.hpp"

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
inline constexpr std::uint8_t fast_sync_read = 0x8A;
inline constexpr std::uint8_t bulk_read = 0x92;
inline constexpr std::uint8_t bulk_write = 0x93;
inline constexpr std::uint8_t fast_bulk_read = 0x9A;
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

// Operating Modes: position control (one turn), extended position control
// (multi-turn, +-256 turns), and position control whose torque Goal Current
// limits.
inline constexpr std::uint8_t kPositionMode = 3;
inline constexpr std::uint8_t kExtendedPositionMode = 4;
inline constexpr std::uint8_t kCurrentBasedPositionMode = 5;

// X-series control table (the addresses the runtime and simulator use).
namespace xreg {
inline constexpr std::uint16_t model_number = 0;            // 2 bytes
inline constexpr std::uint16_t firmware_version = 6;        // 1
inline constexpr std::uint16_t id = 7;                      // 1
inline constexpr std::uint16_t baud_rate = 8;               // 1
inline constexpr std::uint16_t return_delay_time = 9;       // 1, unit 2 us
inline constexpr std::uint16_t operating_mode = 11;         // 1, 3 = position
inline constexpr std::uint16_t homing_offset = 20;          // 4, signed: added to the count
inline constexpr std::uint16_t current_limit = 38;          // 2, unit as Present Current
inline constexpr std::uint16_t velocity_limit = 44;         // 4, unit 0.229 rpm
inline constexpr std::uint16_t max_position_limit = 48;     // 4
inline constexpr std::uint16_t min_position_limit = 52;     // 4
inline constexpr std::uint16_t torque_enable = 64;          // 1
inline constexpr std::uint16_t led = 65;                    // 1
inline constexpr std::uint16_t status_return_level = 68;    // 1
inline constexpr std::uint16_t hardware_error_status = 70;  // 1
// 1, units of 20 ms (1..127, 0 off); reads 0xFF (-1) once it fired, and then
// Goal PWM/Current/Velocity/Position refuse writes (Data Range Error) until
// 0 is written.
inline constexpr std::uint16_t bus_watchdog = 98;
inline constexpr std::uint16_t goal_current = 102;         // 2, signed
inline constexpr std::uint16_t goal_position = 116;        // 4
inline constexpr std::uint16_t moving = 122;               // 1
inline constexpr std::uint16_t present_velocity = 128;     // 4
inline constexpr std::uint16_t present_position = 132;     // 4
inline constexpr std::uint16_t present_temperature = 146;  // 1
// Indirect Address n (2 bytes each) names the register Indirect Data n (1
// byte) stands for: n = 1..28 at 168 / 224, n = 29..56 at 578 / 634.
inline constexpr std::uint16_t indirect_address_1 = 168;
inline constexpr std::uint16_t indirect_data_1 = 224;
inline constexpr std::uint16_t indirect_address_29 = 578;
inline constexpr std::uint16_t indirect_data_29 = 634;
inline constexpr std::uint16_t indirect_count = 28;  // per block
inline constexpr std::uint16_t table_size = 662;     // through Indirect Data 56 (661)
}  // namespace xreg

// What Bus Watchdog (xreg::bus_watchdog) reads once it fired (-1).
inline constexpr std::uint8_t kBusWatchdogFired = 0xFF;

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
std::size_t encode_write(std::uint8_t id, std::uint16_t address, std::span<const std::uint8_t> data,
                         std::span<std::uint8_t> out);
// Sync Read: broadcast; the devices in `ids` answer in that order.
std::size_t encode_sync_read(std::uint16_t address, std::uint16_t length,
                             std::span<const std::uint8_t> ids, std::span<std::uint8_t> out);
// Sync Write: `data` holds ids.size() blocks of `length` bytes, in id order.
std::size_t encode_sync_write(std::uint16_t address, std::uint16_t length,
                              std::span<const std::uint8_t> ids, std::span<const std::uint8_t> data,
                              std::span<std::uint8_t> out);
// Fast Sync Read: laid out as Sync Read; the devices answer with one
// combined status packet (see FastStatusWriter / FastStatusReader).
std::size_t encode_fast_sync_read(std::uint16_t address, std::uint16_t length,
                                  std::span<const std::uint8_t> ids, std::span<std::uint8_t> out);
// One device's part of a (Fast) Bulk Read.
struct BulkReadEntry {
  std::uint8_t id = 0;
  std::uint16_t address = 0;
  std::uint16_t length = 0;
};
std::size_t encode_bulk_read(std::span<const BulkReadEntry> entries, std::span<std::uint8_t> out);
std::size_t encode_fast_bulk_read(std::span<const BulkReadEntry> entries,
                                  std::span<std::uint8_t> out);
// Status packet: error byte then data.
std::size_t encode_status(std::uint8_t id, std::uint8_t error, std::span<const std::uint8_t> data,
                          std::span<std::uint8_t> out);

// The status packet of a Fast Sync Read / Fast Bulk Read: one packet with
// the broadcast id, built by all the devices asked, in the order asked:
//
//   FF FF FD 00 FE LEN_L LEN_H 55 | ERR ID DATA.. CRC_L CRC_H | ERR ID DATA.. CRC | ...
//
// The first device sends the header, whose LEN counts every device's slice;
// each slice ends with the CRC of the whole packet up to that point, so the
// last slice's CRC is the packet's. No byte stuffing (the manual says so).
inline constexpr std::size_t kFastHeaderSize = 8;     // FF FF FD 00 FE LEN LEN 55
inline constexpr std::size_t kFastSliceOverhead = 4;  // ERR ID .. CRC_L CRC_H
// Bytes on the wire of a fast status packet with these data lengths.
std::size_t fast_status_size(std::size_t devices, std::size_t data_bytes);

// Device side: appends slices to one packet in `out`. No allocation.
class FastStatusWriter {
 public:
  // `data_bytes` is the sum of every asked device's data length.
  FastStatusWriter(std::span<std::uint8_t> out, std::size_t devices, std::size_t data_bytes);
  // The header; the first device that answers sends it.
  void header();
  // One device's slice; false if `out` is full.
  bool slice(std::uint8_t error, std::uint8_t id, std::span<const std::uint8_t> data);
  std::size_t size() const { return size_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t length_ = 0;  // LEN field
  std::size_t size_ = 0;
  bool overflow_ = false;
};

// One device's part of a fast status packet.
struct FastSlice {
  std::uint8_t error = 0;
  std::uint8_t id = 0;
  std::span<const std::uint8_t> data;
};

// Master side: walks a fast status packet (complete, or cut short by a device
// that did not answer) slice by slice, checking each slice's own CRC, so that
// the slices before a damaged or missing one are still usable.
class FastStatusReader {
 public:
  // `bytes` as received; anything before the status header (an echo of our
  // own instruction, junk) is skipped.
  explicit FastStatusReader(std::span<const std::uint8_t> bytes);
  bool has_header() const { return start_ != kNone; }
  // Bytes the header announces (header + LEN), once the header is in.
  std::size_t announced_size() const;
  bool complete() const;  // every announced byte is in
  // Bytes received after the header (0 without one).
  std::size_t after_header() const;
  // The id of the next slice, if its first two bytes are in.
  bool peek_id(std::uint8_t& id) const;
  enum class Step : std::uint8_t {
    slice,    // `out` holds the next slice
    end,      // no further bytes
    short_,   // the next slice is cut short
    bad_crc,  // the next slice's CRC does not match (reading stops)
  };
  Step next(std::size_t data_length, FastSlice& out);

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::span<const std::uint8_t> bytes_;
  std::size_t start_ = kNone;  // header position
  std::size_t pos_ = 0;        // next slice
  std::uint16_t crc_ = 0;      // CRC of bytes_[start_, pos_)
  bool stopped_ = false;
};

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
  void reset() { rx_.reset(); }
  // Appends bytes; returns how many fitted (the rest must be fed again later).
  std::size_t feed(std::span<const std::uint8_t> bytes) { return rx_.feed(bytes); }
  DecodeResult next(Packet& out);
  std::uint64_t stray_bytes() const { return rx_.stray(); }
  std::size_t buffered() const { return rx_.size(); }

 private:
  servo::RxBuffer<2 * kMaxPacket> rx_;
  std::uint8_t unstuffed_[kMaxPacket]{};
};

}  // namespace animrt::dxl
