// Feetech SCS/STS stream decoder: arbitrary bytes, fed in chunks whose sizes
// come from the input, must never read out of bounds or stall with a full
// buffer, and every packet it hands out must encode back to the bytes it was
// decoded from (so the checksum and length were checked).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "animrt/bridge/feetech/feetech_codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::ft;
  if (size < 1) return 0;
  const std::size_t chunk = 1 + data[0] % 64;  // bytes per read() of the transport
  ++data;
  --size;
  static Decoder decoder;
  decoder.reset();
  std::array<std::uint8_t, kMaxPacket> again{};
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
      if (r != DecodeResult::packet) continue;
      if (p.raw.size() > kMaxPacket || p.params.size() + 6 != p.raw.size()) std::abort();
      const std::size_t m = encode_packet(p.id, p.code, p.params, again);
      if (m != p.raw.size() || std::memcmp(again.data(), p.raw.data(), m) != 0) std::abort();
    }
    if (!progress) std::abort();  // buffer full and nothing decodable: the stream is stuck
  }
  return 0;
}
