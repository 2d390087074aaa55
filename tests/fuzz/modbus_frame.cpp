// Modbus requests as the simulated drive reads them: the RTU byte stream is
// split into frames the way the drive's server loop does it, CRC-checked,
// and every register write (the input itself also as one TCP PDU) parsed
// for the drive's value checks. The input is an exact-size heap buffer, so a
// read past a frame's declared values is caught.

#include "animrt/sim/modbus/modbus_frame.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace {

void check_write(const std::uint8_t* pdu, std::size_t length) {
  animrt::sim::modbus_frame::Write w;
  if (!animrt::sim::modbus_frame::parse_write(pdu, length, w)) return;
  volatile std::uint16_t sink = 0;
  for (int i = 0; i < w.count; ++i) sink = static_cast<std::uint16_t>(sink ^ w.value(i));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mf = animrt::sim::modbus_frame;
  check_write(data, size);
  std::size_t pos = 0;
  while (pos < size) {
    const std::size_t have = size - pos;
    const int want = mf::rtu_length(data + pos, have);
    if (want == 0 || want > static_cast<int>(have)) break;  // cut: dropped after the silence
    if (want < 0) {  // unknown function: the silence drops the rest
      break;
    }
    const auto len = static_cast<std::size_t>(want);
    if (len < 4) std::abort();  // no room for address, function and CRC
    // Each frame in a buffer of its own size, like an exact-size read.
    const std::vector<std::uint8_t> frame(data + pos, data + pos + len);
    const std::uint16_t crc = mf::crc16(frame.data(), len - 2);
    if ((frame[len - 2] | (frame[len - 1] << 8)) == crc) check_write(frame.data() + 1, len - 3);
    pos += len;
  }
  return 0;
}
