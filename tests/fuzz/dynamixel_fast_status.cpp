// Dynamixel Fast Sync/Bulk Read status packets: arbitrary bytes (a damaged,
// cut short or forged combined status packet) read slice by slice with data
// lengths from the input must never read out of bounds, hand out a slice
// outside the input, or loop forever.

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "animrt/bridge/dynamixel/protocol2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::dxl;
  if (size < 1) return 0;
  const std::size_t length = data[0] % 16;  // each slice's data length
  ++data;
  --size;
  FastStatusReader reader({data, size});
  if (reader.has_header() && reader.announced_size() < 7) std::abort();  // header + LEN
  std::size_t slices = 0;
  for (;;) {
    std::uint8_t id = 0;
    const bool peeked = reader.peek_id(id);
    FastSlice s;
    const auto step = reader.next(length, s);
    if (step != FastStatusReader::Step::slice) break;
    if (!peeked || s.id != id || s.data.size() != length) std::abort();
    if (s.data.data() < data || s.data.data() + s.data.size() > data + size) std::abort();
    if (++slices > size) std::abort();  // every slice consumes bytes
  }
  return 0;
}
