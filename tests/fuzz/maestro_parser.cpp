// Pololu Maestro command stream, as the simulated board reads its RX line.

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "animrt/bridge/maestro/maestro_codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt::maestro;
  Parser parser;
  for (std::size_t i = 0; i < size; ++i) {
    if (parser.feed(data[i]) != ParseResult::command) continue;
    const Command& c = parser.command();
    if (c.count > kMaxChannels) std::abort();
    volatile std::uint16_t sink = c.value;
    for (std::size_t k = 0; k < c.count; ++k)
      sink = static_cast<std::uint16_t>(sink ^ c.targets[k]);
    (void)data_length(c.command);
  }
  return 0;
}
