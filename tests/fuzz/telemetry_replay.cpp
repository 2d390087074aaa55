// Telemetry CSVs replayed by `animrt replay` (runtime/src/telemetry_replay.cpp):
// any bytes are refused with an InputError or loaded.

#include "animrt/runtime/telemetry_replay.hpp"

#include <cstddef>
#include <cstdint>

#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz.csv");
  try {
    (void)animrt::load_telemetry_csv(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
