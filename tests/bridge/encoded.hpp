#pragma once
// The bytes an encoder wrote: the first n of its buffer.

#include <array>
#include <cstdint>
#include <vector>

#include "animrt/bridge/dynamixel/protocol2.hpp"

namespace animrt::dxl {

inline std::vector<std::uint8_t> encoded(std::size_t n,
                                         const std::array<std::uint8_t, kMaxPacket>& buf) {
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace animrt::dxl
