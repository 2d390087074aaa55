// Audio input (controllers/head/audio.cpp) from a file: libsndfile reads it,
// the RIFF walk checks its declared length; also resampled to 16 kHz when
// it is short.

#include <cstddef>
#include <cstdint>

#include "animrt/controllers/head/audio.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = animrt::fuzz::write_input(data, size, "fuzz.wav");
  try {
    const animrt::head::Audio audio = animrt::head::load_audio(path);
    if (audio.samples.size() <= 48000) (void)animrt::head::resample(audio, 16000);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
