// Modbus register-map YAML (configs/modbus/*.yaml): anything but a valid map
// or an InputError is a finding.

#include "animrt/bridge/modbus/register_map.hpp"

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto map =
        animrt::modbus::load_register_map_text(animrt::fuzz::as_text(data, size), "fuzz_map.yaml");
    std::uint16_t words[2] = {0x1234, 0x5678};
    const double si = map->goal.decode(words);
    map->goal.encode(si, words);
    (void)map->fault_text(0xFFFF);
    (void)map->spans();
  } catch (const animrt::InputError&) {
  }
  return 0;
}
