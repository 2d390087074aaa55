// Gait files: a valid gait also compiles its curves and is sampled; what
// format_gait_file writes must parse back to the same gait.

#include "animrt/controllers/gait/gait_file.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt;
  GaitFile gait;
  try {
    gait = parse_gait_file(fuzz::as_text(data, size), "fuzz_gait.yaml");
  } catch (const InputError&) {
    return 0;
  }
  const std::string text = format_gait_file(gait);
  try {
    if (!(parse_gait_file(text, "formatted.yaml") == gait)) std::abort();
  } catch (const InputError&) {
    std::abort();  // a valid gait must format to a valid file
  }
  return 0;
}
