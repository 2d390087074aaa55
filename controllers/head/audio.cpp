// Audio files through libsndfile; resampling through libsamplerate.

#include "animrt/controllers/head/audio.hpp"

#include <samplerate.h>
#include <sndfile.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "animrt/core/error.hpp"

namespace animrt::head {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& message) {
  throw InputError(Location{path, 0, 0}, "", message);
}

std::uint32_t le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// libsndfile quietly reads what is there when a WAV's data chunk is cut
// short; a cut recording would then train on half an utterance. Walk the
// RIFF chunks and compare the declared data size with the bytes present.
void check_riff_length(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[12];
  if (!in.read(reinterpret_cast<char*>(header), 12)) return;
  if (std::string(reinterpret_cast<char*>(header), 4) != "RIFF" ||
      std::string(reinterpret_cast<char*>(header) + 8, 4) != "WAVE") {
    return;
  }
  const auto file_size = static_cast<std::uint64_t>(std::filesystem::file_size(path));
  std::uint64_t pos = 12;
  unsigned char chunk[8];
  while (pos + 8 <= file_size) {
    in.seekg(static_cast<std::streamoff>(pos));
    if (!in.read(reinterpret_cast<char*>(chunk), 8)) return;
    const std::string id(reinterpret_cast<char*>(chunk), 4);
    const std::uint64_t size = le32(chunk + 4);
    // Streaming writers leave 0 or 0xFFFFFFFF in the size; nothing to check.
    if (id == "data" && size != 0 && size != 0xFFFFFFFFu) {
      const std::uint64_t present = file_size - (pos + 8);
      if (present < size) {
        fail(path, "truncated WAV file: the data chunk declares " + std::to_string(size) +
                       " bytes but only " + std::to_string(present) + " are present");
      }
      return;
    }
    pos += 8 + size + (size & 1);
  }
}

}  // namespace

Audio load_audio(const std::string& path, int target_rate) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "audio file not found");
  if (fs::is_directory(path, ec)) fail(path, "expected an audio file, found a folder");
  if (fs::file_size(path, ec) == 0) fail(path, "empty file (0 bytes), expected audio");

  check_riff_length(path);  // before sf_open: a throw here leaves nothing open
  SF_INFO info{};
  SNDFILE* file = sf_open(path.c_str(), SFM_READ, &info);
  if (file == nullptr) {
    fail(path, std::string("not a readable audio file (libsndfile: ") + sf_strerror(nullptr) + ")");
  }
  if (info.frames <= 0 || info.channels <= 0) {
    sf_close(file);
    fail(path, "the audio file holds no samples");
  }
  // libsamplerate converts by a factor of at most 256 either way.
  if (info.samplerate <= 0 ||
      (target_rate > 0 && (static_cast<double>(target_rate) > 256.0 * info.samplerate ||
                           256.0 * target_rate < static_cast<double>(info.samplerate)))) {
    sf_close(file);
    fail(path, "sample rate " + std::to_string(info.samplerate) + " Hz cannot be resampled to " +
                   std::to_string(target_rate) + " Hz");
  }
  std::vector<float> interleaved(static_cast<std::size_t>(info.frames) *
                                 static_cast<std::size_t>(info.channels));
  const sf_count_t got = sf_readf_float(file, interleaved.data(), info.frames);
  sf_close(file);
  if (got != info.frames) {
    fail(path, "truncated audio file: expected " + std::to_string(info.frames) + " frames, read " +
                   std::to_string(got));
  }
  Audio audio;
  audio.sample_rate = info.samplerate;
  audio.samples.resize(static_cast<std::size_t>(got));
  const auto channels = static_cast<std::size_t>(info.channels);
  for (std::size_t i = 0; i < audio.samples.size(); ++i) {
    float sum = 0.0f;
    for (std::size_t c = 0; c < channels; ++c) sum += interleaved[i * channels + c];
    audio.samples[i] = sum / static_cast<float>(channels);
  }
  if (target_rate > 0) audio = resample(audio, target_rate);
  return audio;
}

Audio resample(const Audio& in, int target_rate) {
  if (target_rate <= 0) throw std::invalid_argument("resample: target rate must be positive");
  if (in.sample_rate == target_rate || in.samples.empty()) {
    Audio out = in;
    out.sample_rate = target_rate;
    return out;
  }
  const double ratio = static_cast<double>(target_rate) / in.sample_rate;
  Audio out;
  out.sample_rate = target_rate;
  out.samples.resize(static_cast<std::size_t>(static_cast<double>(in.samples.size()) * ratio) + 16);
  SRC_DATA data{};
  data.data_in = in.samples.data();
  data.input_frames = static_cast<long>(in.samples.size());
  data.data_out = out.samples.data();
  data.output_frames = static_cast<long>(out.samples.size());
  data.src_ratio = ratio;
  const int err = src_simple(&data, SRC_SINC_MEDIUM_QUALITY, 1);
  if (err != 0) throw std::runtime_error(std::string("libsamplerate: ") + src_strerror(err));
  out.samples.resize(static_cast<std::size_t>(data.output_frames_gen));
  return out;
}

void write_wav(const std::string& path, const Audio& audio) {
  SF_INFO info{};
  info.samplerate = audio.sample_rate;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* file = sf_open(path.c_str(), SFM_WRITE, &info);
  if (file == nullptr) {
    throw std::runtime_error("cannot write " + path + ": " + sf_strerror(nullptr));
  }
  std::vector<float> clipped(audio.samples.size());
  std::transform(audio.samples.begin(), audio.samples.end(), clipped.begin(),
                 [](float v) { return std::clamp(v, -1.0f, 1.0f); });
  const sf_count_t n = static_cast<sf_count_t>(clipped.size());
  const sf_count_t written = sf_writef_float(file, clipped.data(), n);
  sf_close(file);
  if (written != n) throw std::runtime_error("cannot write all samples to " + path);
}

}  // namespace animrt::head
