// Robot files: written to <work>/robots/, so the relative paths of the
// shipped robots (../gaits, ../modbus, ../head) resolve.

#include "animrt/runtime/robot_config.hpp"

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "robots/fuzz_robot.yaml");
  try {
    (void)animrt::load_robot_config(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
