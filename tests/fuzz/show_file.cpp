// Show files (keyframe tracks, layers, audio reference), read from a path.

#include "animrt/controllers/show/show_file.hpp"

#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "shows_fuzz.yaml");
  try {
    (void)animrt::load_show_file(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
