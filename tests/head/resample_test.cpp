// The analysis resamples a file to the model's rate with a polyphase
// filter (for offline synthesis speed): the features of recorded speech
// stay within a tolerance of those after libsamplerate's medium-quality
// converter; and the filter passes a tone in its band at its level.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/prosody.hpp"

namespace animrt::head {
namespace {

TEST(Resample, TheFastConverterKeepsTheFeaturesOfSpeech) {
  const Audio speech = load_audio(std::string(ANIMRT_SOURCE_DIR) + "/configs/head/utterance.wav");
  ASSERT_NE(speech.sample_rate, FeatureConfig{}.sample_rate);
  const FeatureTrack fast = extract_features(speech, FeatureConfig{});
  const FeatureTrack medium = extract_features(
      resample(speech, FeatureConfig{}.sample_rate, ResampleQuality::medium), FeatureConfig{});
  // The converters may end a sample apart.
  ASSERT_LE(std::max(fast.size(), medium.size()) - std::min(fast.size(), medium.size()), 1u);
  const std::size_t frames = std::min(fast.size(), medium.size());
  std::size_t voicing_differs = 0, both_voiced = 0, f0_off = 0;
  double f0_worst = 0.0, energy_worst = 0.0;
  for (std::size_t i = 0; i < frames; ++i) {
    const RawFrame& a = fast.raw[i];
    const RawFrame& b = medium.raw[i];
    voicing_differs += a.voiced != b.voiced;
    if (a.voiced && b.voiced) {
      ++both_voiced;
      const double st = std::abs(12.0 * std::log2(a.f0_hz / b.f0_hz));
      f0_worst = std::max(f0_worst, st);
      f0_off += st > 0.1;
    }
    energy_worst =
        std::max(energy_worst, std::abs(fast.features(static_cast<Eigen::Index>(i), 1) -
                                        medium.features(static_cast<Eigen::Index>(i), 1)));
  }
  std::printf(
      "%zu frames: voicing differs in %zu, F0 > 0.1 st apart in %zu of %zu (worst %.3f st), "
      "energy worst %.3f dB\n",
      fast.size(), voicing_differs, f0_off, both_voiced, f0_worst, energy_worst);
  EXPECT_GT(both_voiced, frames / 4);
  EXPECT_LE(voicing_differs, frames / 100);  // 1 %
  EXPECT_LE(f0_off, both_voiced / 100);
  EXPECT_LT(energy_worst, 0.5);
}

// A tone in the band comes out at its level and phase, sample for sample
// (the output placed as libsamplerate places it), for an upsampling and a
// downsampling ratio.
TEST(Resample, ATonePassesAtItsLevelAndPhase) {
  for (const auto& [from, to] : {std::pair{22050, 24000}, std::pair{44100, 24000}}) {
    Audio tone;
    tone.sample_rate = from;
    for (int i = 0; i < from / 2; ++i) {
      tone.samples.push_back(static_cast<float>(0.5 * std::sin(2.0 * M_PI * 1000.0 * i / from)));
    }
    const Audio out = resample(tone, to);
    ASSERT_EQ(out.sample_rate, to);
    ASSERT_NEAR(static_cast<double>(out.samples.size()), to / 2.0, 1.0);
    double worst = 0.0;
    for (std::size_t n = 100; n + 100 < out.samples.size(); ++n) {
      const double want = 0.5 * std::sin(2.0 * M_PI * 1000.0 * static_cast<double>(n) / to);
      worst = std::max(worst, std::abs(out.samples[n] - want));
    }
    EXPECT_LT(worst, 1e-3) << from << " -> " << to;
  }
}

}  // namespace
}  // namespace animrt::head
