#pragma once
// Dynamixel Protocol 2.0 exchanges of the commissioning tools: the
// bridge's codec, one instruction at a time, every answer kept.

#include <chrono>
#include <cstdint>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"

namespace animrt::commission::dxl_detail {

// A ping's status packet: header 4, id, length 2, 0x55, error, model 2,
// firmware, CRC 2.
inline constexpr std::size_t kPingStatusBytes = 14;
// Present Input Voltage (2 bytes, 0.1 V) of the X series.
inline constexpr std::uint16_t kPresentInputVoltage = 144;
// Addresses 0..147: every EEPROM item and the present values a scan shows.
inline constexpr std::uint16_t kScanTableBytes = 148;

struct Status {
  int id = 0;
  std::uint8_t error = 0;
  std::vector<std::uint8_t> data;
};

struct Statuses {
  std::vector<Status> packets;  // status packets that checked out, in order
  int damaged = 0;              // packets dropped for a bad CRC or length
  std::set<int> header_ids;     // ids named by any status header, damaged or not
  std::size_t stray = 0;        // bytes outside any packet that checked out
};

// Decodes every status packet in `bytes` (the echo of an instruction is skipped).
Statuses decode(std::span<const std::uint8_t> bytes);

// A unicast ping: every answer, decoded.
Statuses ping(ByteTransport& line, std::uint8_t id, int baud, std::chrono::microseconds timeout);

// A unicast read: the data, or nothing when no clean status came (or it
// carried an error number).
std::optional<std::vector<std::uint8_t>> read(ByteTransport& line, std::uint8_t id,
                                              std::uint16_t address, std::uint16_t length, int baud,
                                              std::chrono::microseconds timeout);

// A unicast instruction: the error byte of the one status packet, or -1 when
// none (or a damaged one) came; `answers` gets how many came.
int instruct(ByteTransport& line, std::uint8_t id, std::uint8_t instruction,
             std::span<const std::uint8_t> params, int baud, std::chrono::microseconds timeout,
             int* answers = nullptr);

// Operating Mode names (X series): current, velocity, position,
// extended-position, current-position, pwm.
std::string mode_name(std::uint8_t mode);
std::optional<std::uint8_t> mode_value(const std::string& name);
std::string mode_names();

// "Error number N (meaning)" of a status packet.
std::string describe_error(std::uint8_t error);

}  // namespace animrt::commission::dxl_detail
