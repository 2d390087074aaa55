#pragma once
// The simulated drive's own reading of Modbus requests, apart from libmodbus:
// RTU framing (a frame's length follows from its function code), the RTU
// CRC, and the written values of a write request, which the drive checks
// before libmodbus stores them.

#include <cstddef>
#include <cstdint>

namespace animrt::sim::modbus_frame {

// CRC-16/MODBUS (poly 0xA001 reflected, init 0xFFFF); sent low byte first.
std::uint16_t crc16(const std::uint8_t* p, std::size_t n);

// Length of an RTU request from its first `have` bytes: 0 = not known yet,
// -1 = unknown function code.
int rtu_length(const std::uint8_t* frame, std::size_t have);

// The registers a request writes: function 6, 16 or 23. `values` holds
// `count` big-endian words, all inside the PDU.
struct Write {
  int address = 0;
  int count = 0;
  const std::uint8_t* values = nullptr;
  std::uint16_t value(int i) const {
    return static_cast<std::uint16_t>((values[2 * i] << 8) | values[2 * i + 1]);
  }
};

// False when the PDU (function code first, `length` bytes) is no register
// write, or is cut short or declares more values than it carries; libmodbus
// then answers it (with an exception where it is malformed).
bool parse_write(const std::uint8_t* pdu, std::size_t length, Write& out);

}  // namespace animrt::sim::modbus_frame
