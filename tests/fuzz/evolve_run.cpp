// Evolution run files (configs/evolve/*.yaml); relative paths resolve as
// from configs/evolve/.

#include <cstddef>
#include <cstdint>

#include "animrt/learn/evolve/run_config.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)animrt::evolve::parse_run_config(animrt::fuzz::as_text(data, size),
                                           animrt::fuzz::work_dir() + "/robots/fuzz_run.yaml");
  } catch (const animrt::InputError&) {
  }
  return 0;
}
