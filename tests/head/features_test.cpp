// Prosodic features on synthetic tones of known pitch; WAV errors.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "animrt/controllers/head/prosody.hpp"
#include "animrt/core/error.hpp"
#include "head_test_util.hpp"

namespace animrt::head {
namespace {

using test::concat;
using test::silence;
using test::tone;

TEST(Features, ToneOfKnownPitchIsVoicedAtThatPitch) {
  for (double f0 : {110.0, 150.0, 220.0, 310.0}) {
    const FeatureTrack t = extract_features(tone(f0, 0.5), FeatureConfig{});
    ASSERT_GT(t.size(), 50u);
    int voiced = 0;
    for (std::size_t i = 5; i + 5 < t.size(); ++i) {
      if (!t.raw[i].voiced) continue;
      ++voiced;
      EXPECT_NEAR(t.raw[i].f0_hz, f0, f0 * 0.02) << "frame " << i;
    }
    EXPECT_GT(voiced, static_cast<int>(t.size()) - 12) << f0;
  }
}

TEST(Features, FrameRateAndTimes) {
  const FeatureConfig c;
  const FeatureTrack t = extract_features(tone(200, 1.0), c);
  // 1 s at 24 kHz: (24000 - 600) / 200 + 1 frames, the first at 12.5 ms.
  EXPECT_EQ(t.size(), 118u);
  EXPECT_DOUBLE_EQ(t.frame_rate_hz, 120.0);
  EXPECT_NEAR(t.time(0), 0.0125, 1e-12);
  EXPECT_NEAR(t.time(10) - t.time(9), 1.0 / 120, 1e-12);
  EXPECT_EQ(t.features.cols(), 6);
}

TEST(Features, RmsEnergyOfASine) {
  Audio a;
  a.sample_rate = 24000;
  for (int i = 0; i < 24000; ++i)
    a.samples.push_back(
        static_cast<float>(0.4 * std::sin(2 * std::numbers::pi * 240 * i / 24000.0)));
  const FeatureTrack t = extract_features(a, FeatureConfig{});
  for (std::size_t i = 0; i < t.size(); ++i)
    EXPECT_NEAR(t.raw[i].energy, 0.4 / std::sqrt(2.0), 2e-3);
}

TEST(Features, SilenceIsUnvoicedAndGapsAreFilled) {
  const Audio a = concat(concat(tone(150, 0.4), silence(0.3)), tone(200, 0.4));
  const FeatureTrack t = extract_features(a, FeatureConfig{});
  // Middle of the silence: unvoiced, raw F0 0, filled F0 between the tones.
  const auto mid = static_cast<std::size_t>((0.55 - t.t0_s) * 120);
  EXPECT_FALSE(t.raw[mid].voiced);
  EXPECT_EQ(t.raw[mid].f0_hz, 0.0);
  EXPECT_GT(t.f0_filled[mid], 140.0);
  EXPECT_LT(t.f0_filled[mid], 210.0);
  // The observation is F0 in semitones above 100 Hz and energy in dB:
  // 150 Hz is 7.02 st, 200 Hz is 12 st; silence sits at the -60 dB floor.
  const auto row = [&](double t_s) { return static_cast<Eigen::Index>((t_s - t.t0_s) * 120); };
  EXPECT_NEAR(t.features(row(0.2), 0), 12.0 * std::log2(1.5), 0.15);
  EXPECT_NEAR(t.features(row(0.9), 0), 12.0, 0.15);
  EXPECT_NEAR(t.features(row(0.2), 1),
              20.0 * std::log10(t.raw[static_cast<std::size_t>(row(0.2))].energy), 1e-9);
  EXPECT_EQ(t.features(row(0.55), 1), kEnergyFloorDb);
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(t.features(static_cast<Eigen::Index>(i), 0), f0_semitones(t.f0_filled[i]), 1e-9);
    EXPECT_GE(t.f0_filled[i], 80.0);
    EXPECT_LE(t.f0_filled[i], 500.0);
  }
}

TEST(Features, DeltasOfARampAreItsSlope) {
  Eigen::MatrixXd x(20, 1);
  for (int i = 0; i < 20; ++i) x(i, 0) = 3.0 * i;
  const Eigen::MatrixXd d = deltas(x, 2, 120.0);
  for (int i = 2; i < 18; ++i) EXPECT_NEAR(d(i, 0), 3.0 * 120.0, 1e-9);
  const Eigen::MatrixXd dd = deltas(d, 2, 120.0);
  for (int i = 4; i < 16; ++i) EXPECT_NEAR(dd(i, 0), 0.0, 1e-9);
}

TEST(Features, ResamplesAnyInputRate) {
  const FeatureTrack a = extract_features(tone(180, 0.5, 44100), FeatureConfig{});
  const FeatureTrack b = extract_features(tone(180, 0.5, 8000), FeatureConfig{});
  EXPECT_NEAR(a.raw[30].f0_hz, 180, 3.6);
  EXPECT_NEAR(b.raw[30].f0_hz, 180, 3.6);
}

// ------------------------------------------------------------ bad audio

std::string expect_input_error(const std::string& path) {
  try {
    load_audio(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    return e.what();
  }
  ADD_FAILURE() << "no InputError for " << path;
  return "";
}

TEST(AudioFiles, MissingEmptyTruncatedAndNonAudioFilesAreClearErrors) {
  const std::string dir = test::temp_dir("badaudio");
  EXPECT_NE(expect_input_error(dir + "/nope.wav").find("not found"), std::string::npos);

  std::ofstream(dir + "/empty.wav").close();
  EXPECT_NE(expect_input_error(dir + "/empty.wav").find("empty"), std::string::npos);

  std::ofstream(dir + "/text.wav") << "this is not audio at all, just some words\n";
  EXPECT_NE(expect_input_error(dir + "/text.wav").find("not a readable audio file"),
            std::string::npos);

  write_wav(dir + "/good.wav", tone(150, 0.5));
  const auto size = std::filesystem::file_size(dir + "/good.wav");
  std::filesystem::copy_file(dir + "/good.wav", dir + "/cut.wav");
  std::filesystem::resize_file(dir + "/cut.wav", size / 2);
  EXPECT_NE(expect_input_error(dir + "/cut.wav").find("truncated"), std::string::npos);

  // A header alone: no samples.
  std::filesystem::copy_file(dir + "/good.wav", dir + "/header.wav");
  std::filesystem::resize_file(dir + "/header.wav", 44);
  expect_input_error(dir + "/header.wav");

  const Audio ok = load_audio(dir + "/good.wav");
  EXPECT_EQ(ok.sample_rate, 16000);
  EXPECT_EQ(ok.samples.size(), 8000u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace animrt::head

namespace animrt::head {
namespace {

// Found by the wav_audio fuzz harness: a WAV header declaring 1845501760 Hz
// made libsamplerate throw a bare runtime_error (ratio outside 1/256..256)
// instead of an error naming the file.
TEST(AudioFiles, AnAbsurdSampleRateIsAClearErrorBeforeResampling) {
  const unsigned char wav[] = {
      0x52, 0x49, 0x46, 0x46, 0x14, 0x01, 0x00, 0x00, 0x57, 0x41, 0x56, 0x45, 0x66, 0x6d,
      0x74, 0x20, 0x10, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00, 0x40, 0x1f, 0x00, 0x6e,
      0x80, 0x3e, 0x00, 0x00, 0x02, 0x00, 0x10, 0x00, 0x64, 0x61, 0x74, 0x61, 0xff, 0xff,
      0xff, 0xff, 0x00, 0x00, 0xad, 0x15, 0xcb, 0xf4, 0x6d, 0xdf, 0xb1, 0xce, 0xca, 0xc3};
  const std::string dir = test::temp_dir("fastaudio");
  const std::string path = dir + "/fast.wav";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(wav), sizeof wav);
  try {
    load_audio(path, 16000);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, path);
    EXPECT_NE(
        std::string(e.what()).find("sample rate 1845501760 Hz in the header, expected 4000..384000 Hz"),
        std::string::npos)
        << e.what();
  }
  // Nor without resampling: the rate is out of range before anything is read.
  EXPECT_THROW(load_audio(path), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace animrt::head
