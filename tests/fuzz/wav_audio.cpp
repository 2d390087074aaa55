// Audio input (controllers/head/audio.cpp) from a file: libsndfile reads it,
// the RIFF walk checks its declared length, and it is resampled to 16 kHz as
// the head's feature extraction asks for.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz.wav");
  try {
    (void)animrt::head::load_audio(path, 16000);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
