#pragma once
// Feetech SCS/STS exchanges of the commissioning tools (see dxl_packets.hpp).

#include <chrono>
#include <cstdint>
#include <optional>
#include <set>
#include <span>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/feetech/feetech_codec.hpp"

namespace animrt::commission::ft_detail {

struct Status {
  int id = 0;
  std::uint8_t error = 0;
  std::vector<std::uint8_t> data;
};

struct Statuses {
  std::vector<Status> packets;
  int damaged = 0;
  std::set<int> header_ids;  // ids named by any header, damaged or not (the echo left out)
  std::size_t bytes = 0;     // received, the echo left out
};

// Every packet in `bytes` except the echo of `sent`.
Statuses decode(std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> sent);

// One instruction to `id`: every answer.
Statuses transact(ByteTransport& line, std::uint8_t id, std::uint8_t instruction,
                  std::span<const std::uint8_t> params, std::size_t answer_bytes, int baud,
                  std::chrono::microseconds timeout);

std::optional<std::vector<std::uint8_t>> read(ByteTransport& line, std::uint8_t id,
                                              std::uint8_t address, std::uint8_t length, int baud,
                                              std::chrono::microseconds timeout);

// The series whose byte order makes the angle limits of a memory table
// (address 0 on) plausible: STS limits fit 0..4095 low byte first, SCS
// 0..1023 high byte first.
ft::Series guess_series(std::span<const std::uint8_t> table);

}  // namespace animrt::commission::ft_detail
