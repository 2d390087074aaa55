// Sequence feature files (controllers/seqnet/feature_file.cpp): any bytes
// are refused with an InputError or read; no count in the header sizes
// anything before it is checked against the file's length.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz.feat");
  try {
    (void)animrt::seqnet::read_feature_file(path);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
