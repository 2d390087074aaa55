// MCAP recordings read by `animrt view` (runtime/src/mcap_reader.cpp and the
// JointStates of runtime/src/telemetry_replay.cpp): any bytes are refused
// with an InputError or read.

#include "animrt/runtime/mcap_reader.hpp"

#include <cstddef>
#include <cstdint>

#include "animrt/core/error.hpp"
#include "animrt/runtime/telemetry_replay.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)animrt::mcap::read_bytes({data, size}, "fuzz.mcap");
  } catch (const animrt::InputError&) {
  }
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz.mcap");
  try {
    (void)animrt::load_telemetry_mcap(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
