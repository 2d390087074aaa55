// Head model files (controllers/head/model_io.cpp), read from a path.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/head/model.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz_model.txt");
  try {
    (void)animrt::head::load_model(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
