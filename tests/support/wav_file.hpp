#pragma once
// Mono float WAVs for the tests, written in one call (libsndfile); shared
// for the same reason as files.hpp.

#include <sndfile.h>

#include <string>
#include <vector>

namespace animrt {

// Writes `samples` as a mono WAV of 32-bit floats at `rate` Hz; false when
// the file cannot be written.
inline bool write_float_wav(const std::string& path, const std::vector<float>& samples, int rate) {
  SF_INFO info{};
  info.samplerate = rate;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  SNDFILE* f = sf_open(path.c_str(), SFM_WRITE, &info);
  if (f == nullptr) return false;
  const auto n = static_cast<sf_count_t>(samples.size());
  const bool all = sf_writef_float(f, samples.data(), n) == n;
  return sf_close(f) == 0 && all;
}

}  // namespace animrt
