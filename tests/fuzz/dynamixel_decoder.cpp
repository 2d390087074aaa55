// Dynamixel Protocol 2.0 stream decoder: arbitrary bytes, fed in chunks whose
// sizes come from the input, must never read out of bounds, stall with a
// full buffer, or hand out a packet that does not fit its buffer.

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "animrt/bridge/dynamixel/protocol2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::dxl;
  if (size < 1) return 0;
  const std::size_t chunk = 1 + data[0] % 64;  // bytes per read() of the transport
  ++data;
  --size;
  static Decoder decoder;  // big buffers: one instance, reset per input
  decoder.reset();
  std::size_t pos = 0;
  while (pos < size) {
    const std::size_t n = chunk < size - pos ? chunk : size - pos;
    const std::size_t fed = decoder.feed({data + pos, n});
    pos += fed;
    Packet p;
    DecodeResult r;
    bool progress = fed > 0;
    while ((r = decoder.next(p)) != DecodeResult::need_more) {
      progress = true;
      if (r == DecodeResult::packet) {
        if (p.params.size() > kMaxPacket) std::abort();
        volatile std::uint8_t sink = 0;
        for (std::uint8_t b : p.params) sink = static_cast<std::uint8_t>(sink ^ b);
      }
    }
    if (!progress) std::abort();  // buffer full and nothing decodable: the stream is stuck
  }
  return 0;
}
