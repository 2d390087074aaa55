#pragma once
// One request out, every byte that comes back in: the commissioning tools
// decode the bytes afterwards, so damaged or overlapping answers (several
// servos with one id) can be looked at as a whole.

#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"

namespace animrt::commission::detail {

struct Wait {
  std::chrono::microseconds first{10'000};   // for the first byte
  std::chrono::microseconds quiet{2'000};    // after a byte, silence that ends the answer
  std::chrono::microseconds cap{1'000'000};  // in all
};

// Sends `request` (after dropping stale input) and collects bytes as Wait
// says, or until `done(bytes)` holds.
std::vector<std::uint8_t> exchange(
    ByteTransport& line, std::span<const std::uint8_t> request, const Wait& wait,
    const std::function<bool(std::span<const std::uint8_t>)>& done = {});

// Time on the wire of `bytes` at `baud` (10 bits a byte), rounded up.
std::chrono::microseconds wire_time(std::size_t bytes, int baud);

}  // namespace animrt::commission::detail
