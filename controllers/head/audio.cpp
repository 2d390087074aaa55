// Audio files through libsndfile; resampling through libsamplerate.

#include "animrt/controllers/head/audio.hpp"

#include <samplerate.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "animrt/core/error.hpp"
#include "animrt/core/input_file.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "polyphase.hpp"

namespace animrt::head {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& message) {
  throw InputError(Location{path, 0, 0}, "", message);
}

std::uint32_t le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

}  // namespace

std::string wav_truncation(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[12];
  if (!in.read(reinterpret_cast<char*>(header), 12)) return {};
  if (std::string(reinterpret_cast<char*>(header), 4) != "RIFF" ||
      std::string(reinterpret_cast<char*>(header) + 8, 4) != "WAVE") {
    return {};
  }
  std::error_code ec;
  const auto file_size = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
  if (ec) return {};
  std::uint64_t pos = 12;
  unsigned char chunk[8];
  while (pos + 8 <= file_size) {
    in.seekg(static_cast<std::streamoff>(pos));
    if (!in.read(reinterpret_cast<char*>(chunk), 8)) return {};
    const std::string id(reinterpret_cast<char*>(chunk), 4);
    const std::uint64_t size = le32(chunk + 4);
    // Streaming writers leave 0 or 0xFFFFFFFF in the size; nothing to check.
    if (id == "data" && size != 0 && size != 0xFFFFFFFFu) {
      const std::uint64_t present = file_size - (pos + 8);
      if (present >= size) return {};
      return "truncated WAV file: the data chunk declares " + std::to_string(size) +
             " bytes but only " + std::to_string(present) + " are present";
    }
    pos += 8 + size + (size & 1);
  }
  return {};
}

namespace {

// Frames read and mixed at a time.
constexpr sf_count_t kChunkFrames = 16384;
// A compressed file (FLAC, Ogg, MPEG) may declare at most this many samples per
// byte it has, and at least kMinCompressedSamples in any case. Speech and
// music compress to about a byte a sample; digital silence in FLAC (constant
// subframes, about 15 bytes a 4096-sample block) to some 300-500, and a show
// track may be mostly silence. Nothing is sized from the claim (samples are
// read in chunks), so this only refuses a header that cannot be true.
constexpr std::uintmax_t kMaxSamplesPerCompressedByte = 4096;
constexpr std::uintmax_t kMinCompressedSamples = std::uintmax_t{1} << 20;

// Bytes a sample takes in an uncompressed encoding, 0 for a compressed one.
// FLAC, Ogg and MPEG name the decoded bit depth in the subformat: compressed
// whatever it says.
int bytes_per_sample(int format) {
  switch (format & SF_FORMAT_TYPEMASK) {
    case SF_FORMAT_FLAC:
    case SF_FORMAT_OGG:
    case SF_FORMAT_MPEG:
      return 0;
    default:
      break;
  }
  switch (format & SF_FORMAT_SUBMASK) {
    case SF_FORMAT_PCM_S8:
    case SF_FORMAT_PCM_U8:
    case SF_FORMAT_ULAW:
    case SF_FORMAT_ALAW:
      return 1;
    case SF_FORMAT_PCM_16:
      return 2;
    case SF_FORMAT_PCM_24:
      return 3;
    case SF_FORMAT_PCM_32:
    case SF_FORMAT_FLOAT:
      return 4;
    case SF_FORMAT_DOUBLE:
      return 8;
    default:
      return 0;
  }
}

// Why the header's frame count cannot be true of a file of `file_size`
// bytes, or "". Divides rather than multiplies: the count is the header's
// word and may be anything up to 2^63.
std::string frame_count_problem(const SF_INFO& info, std::uintmax_t file_size) {
  const auto frames = static_cast<std::uintmax_t>(info.frames);
  const auto channels = static_cast<std::uintmax_t>(info.channels);
  const std::string claim = "the header declares " + std::to_string(info.frames) + " frames x " +
                            std::to_string(info.channels) + " channels";
  if (const int width = bytes_per_sample(info.format); width > 0) {
    if (frames > file_size / static_cast<std::uintmax_t>(width) / channels) {
      return claim + " of " + std::to_string(width) + " bytes, more than the file's " +
             std::to_string(file_size) + " bytes";
    }
    return "";
  }
  const std::uintmax_t cap =
      std::max(kMinCompressedSamples, file_size * kMaxSamplesPerCompressedByte);
  if (frames > cap / channels) {
    return claim + ", more than " + std::to_string(kMaxSamplesPerCompressedByte) +
           " samples per byte of its " + std::to_string(file_size) + " compressed bytes";
  }
  return "";
}

// The frames of an open file, mixed to mono as they are read in chunks,
// appended to `out` (or only looked at when it is null).
struct MonoRead {
  sf_count_t frames = 0;      // frames read
  sf_count_t nonfinite = -1;  // the first frame whose mix is not a finite number, or -1
};

MonoRead read_mono(SNDFILE* file, const SF_INFO& info, std::vector<float>* out) {
  const auto channels = static_cast<std::size_t>(info.channels);
  std::vector<float> chunk(kChunkFrames * channels);
  MonoRead r;
  while (r.frames < info.frames) {
    const sf_count_t want = std::min<sf_count_t>(kChunkFrames, info.frames - r.frames);
    const sf_count_t n = sf_readf_float(file, chunk.data(), want);
    if (n <= 0) break;
    for (sf_count_t f = 0; f < n; ++f) {
      float sum = 0.0f;
      for (std::size_t c = 0; c < channels; ++c)
        sum += chunk[static_cast<std::size_t>(f) * channels + c];
      const float mono = sum / static_cast<float>(channels);
      if (!std::isfinite(mono)) {
        r.nonfinite = r.frames + f;
        return r;
      }
      if (out) out->push_back(mono);
    }
    r.frames += n;
  }
  return r;
}

std::string nonfinite_problem(sf_count_t frame, int rate) {
  return "sample " + std::to_string(frame) + " (at " +
         format_number(static_cast<double>(frame) / rate) +
         " s) is not a finite number (NaN or infinity)";
}

// Integer encodings (PCM, u-law, A-law; FLAC's subformats are PCM) cannot
// hold a sample that is not a finite number.
bool integer_samples(int format) {
  switch (format & SF_FORMAT_SUBMASK) {
    case SF_FORMAT_PCM_S8:
    case SF_FORMAT_PCM_U8:
    case SF_FORMAT_PCM_16:
    case SF_FORMAT_PCM_24:
    case SF_FORMAT_PCM_32:
    case SF_FORMAT_ULAW:
    case SF_FORMAT_ALAW:
      return true;
    default:
      return false;
  }
}

}  // namespace

std::string audio_nonfinite_sample(const std::string& path) {
  SF_INFO info{};
  SNDFILE* file = sf_open(path.c_str(), SFM_READ, &info);
  if (file == nullptr) return {};
  MonoRead r;
  if (info.frames > 0 && info.channels > 0 && info.samplerate > 0 && !integer_samples(info.format))
    r = read_mono(file, info, nullptr);
  sf_close(file);
  return r.nonfinite >= 0 ? nonfinite_problem(r.nonfinite, info.samplerate) : std::string();
}

Audio load_audio(const std::string& path, int target_rate) {
  namespace fs = std::filesystem;
  if (const std::string problem = input_file_problem(path, kMaxMediaFileBytes); !problem.empty())
    fail(path, problem == kFileMissing ? "audio file not found" : problem);
  std::error_code ec;
  const std::uintmax_t file_size = fs::file_size(path, ec);
  if (file_size == 0) fail(path, "empty file (0 bytes), expected audio");

  // Before sf_open: a throw here leaves nothing open.
  if (const std::string cut = wav_truncation(path); !cut.empty()) fail(path, cut);
  SF_INFO info{};
  SNDFILE* file = sf_open(path.c_str(), SFM_READ, &info);
  if (file == nullptr) {
    fail(path, std::string("not a readable audio file (libsndfile: ") + sf_strerror(nullptr) + ")");
  }
  if (info.frames <= 0 || info.channels <= 0) {
    sf_close(file);
    fail(path, "the audio file holds no samples");
  }
  // Before anything is allocated: a header claiming 1 Hz or 200 channels
  // would otherwise size buffers from nonsense.
  if (info.samplerate < kMinAudioRate || info.samplerate > kMaxAudioRate) {
    sf_close(file);
    fail(path, "sample rate " + std::to_string(info.samplerate) + " Hz in the header, expected " +
                   std::to_string(kMinAudioRate) + ".." + std::to_string(kMaxAudioRate) + " Hz");
  }
  if (info.channels > kMaxAudioChannels) {
    sf_close(file);
    fail(path, std::to_string(info.channels) + " channels in the header, expected 1.." +
                   std::to_string(kMaxAudioChannels));
  }
  // The frame count is the header's word: checked against the file's size
  // before anything is sized from it, and the samples are read in chunks
  // (mixed to mono as they come), so a header that lies costs nothing.
  if (const std::string problem = frame_count_problem(info, file_size); !problem.empty()) {
    sf_close(file);
    fail(path, problem);
  }
  Audio audio;
  audio.sample_rate = info.samplerate;
  audio.samples.reserve(static_cast<std::size_t>(
      std::min<sf_count_t>(info.frames, static_cast<sf_count_t>(file_size))));
  const MonoRead read = read_mono(file, info, &audio.samples);
  sf_close(file);
  if (read.nonfinite >= 0) fail(path, nonfinite_problem(read.nonfinite, info.samplerate));
  if (read.frames != info.frames) {
    fail(path, "truncated audio file: expected " + std::to_string(info.frames) + " frames, read " +
                   std::to_string(read.frames));
  }
  if (target_rate > 0) {
    try {
      audio = resample(audio, target_rate);
    } catch (const std::exception& e) {
      fail(path,
           std::string("cannot resample to ") + std::to_string(target_rate) + " Hz: " + e.what());
    }
  }
  return audio;
}

Audio resample(const Audio& in, int target_rate, ResampleQuality quality) {
  if (target_rate <= 0) throw std::invalid_argument("resample: target rate must be positive");
  if (in.sample_rate == target_rate || in.samples.empty()) {
    Audio out = in;
    out.sample_rate = target_rate;
    return out;
  }
  Audio out;
  out.sample_rate = target_rate;
  if (quality == ResampleQuality::fast &&
      resample_polyphase(in.samples, in.sample_rate, target_rate, out.samples)) {
    return out;
  }
  const double ratio = static_cast<double>(target_rate) / in.sample_rate;
  out.samples.resize(static_cast<std::size_t>(static_cast<double>(in.samples.size()) * ratio) + 16);
  SRC_DATA data{};
  data.data_in = in.samples.data();
  data.input_frames = static_cast<long>(in.samples.size());
  data.data_out = out.samples.data();
  data.output_frames = static_cast<long>(out.samples.size());
  data.src_ratio = ratio;
  const int err = src_simple(
      &data, quality == ResampleQuality::fast ? SRC_SINC_FASTEST : SRC_SINC_MEDIUM_QUALITY, 1);
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
