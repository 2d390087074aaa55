#pragma once
// Mono audio in memory, and WAV (or any libsndfile format) input/output.

#include <string>
#include <vector>

namespace animrt::head {

// Sample rates and channel counts an input file may declare; anything else
// is a damaged or hostile header.
inline constexpr int kMinAudioRate = 4000;
inline constexpr int kMaxAudioRate = 384000;
inline constexpr int kMaxAudioChannels = 64;

struct Audio {
  int sample_rate = 0;
  std::vector<float> samples;  // mono, nominally in [-1, 1]
  double duration_s() const {
    return sample_rate > 0 ? static_cast<double>(samples.size()) / sample_rate : 0.0;
  }
};

// Reads an audio file through libsndfile, mixes it down to mono and, when
// `target_rate` > 0 and differs, resamples it with libsamplerate. Throws
// InputError naming the file for a missing, empty, truncated or non-audio
// file, one that is not a regular file, one whose header declares a rate
// outside kMinAudioRate..kMaxAudioRate, and one holding NaN or infinite
// samples.
Audio load_audio(const std::string& path, int target_rate = 0);

// What is wrong with a WAV file whose data chunk declares more bytes than
// the file holds, or "" (also for a file that is not WAV). libsndfile
// quietly reads what is there, so a cut recording would pass for a whole one.
std::string wav_truncation(const std::string& path);

// What is wrong with the first sample of an audio file that is not a finite
// number (NaN or infinity) once mixed to mono, as load_audio says it, or ""
// (also for a file libsndfile does not open). Reads the whole file unless
// its encoding is an integer one, which cannot hold such a sample.
std::string audio_nonfinite_sample(const std::string& path);

// `fast`: a polyphase windowed-sinc filter for the rational ratio (what the
// analysis uses; its features are tested to stay within a tolerance of
// `medium`'s), libsamplerate's fastest sinc converter for ratios too
// irregular for a table; `medium`: libsamplerate's medium-quality sinc.
enum class ResampleQuality { fast, medium };

// Resamples with libsamplerate. Returns `in` unchanged when the rates match.
Audio resample(const Audio& in, int target_rate, ResampleQuality quality = ResampleQuality::fast);

// Writes 16-bit PCM WAV. Throws std::runtime_error when the file cannot be
// written.
void write_wav(const std::string& path, const Audio& audio);

}  // namespace animrt::head
