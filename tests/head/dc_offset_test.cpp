// A DC offset (a cheap microphone's) is no speech: the prosodic features of
// a sound with an offset are those of the same sound without it, so silence
// with an offset does not tilt the head as speech would.

#include <gtest/gtest.h>

#include <cmath>

#include "animrt/controllers/head/prosody.hpp"
#include "head_test_util.hpp"

namespace animrt::head::dc_offset_test {
namespace {

Audio shifted(Audio a, float dc) {
  for (float& v : a.samples) v += dc;
  return a;
}

TEST(DcOffset, FeaturesOfSpeechWithAnOffsetAreThoseWithout) {
  constexpr int kRate = 24000;  // the analysis rate: no resampler edge
  const Audio plain =
      test::concat(test::concat(test::silence(0.5, kRate), test::tone(150, 0.5, kRate)),
                   test::silence(0.5, kRate));
  const FeatureTrack without = extract_features(plain, FeatureConfig{});
  const FeatureTrack with = extract_features(shifted(plain, 0.05f), FeatureConfig{});
  ASSERT_EQ(with.size(), without.size());
  int voiced = 0;
  for (std::size_t i = 0; i < with.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    EXPECT_EQ(with.raw[i].voiced, without.raw[i].voiced) << "frame " << i;
    voiced += with.raw[i].voiced ? 1 : 0;
    EXPECT_NEAR(with.raw[i].energy, without.raw[i].energy, 1e-6) << "frame " << i;
    EXPECT_NEAR(with.features(r, 1), without.features(r, 1), 1e-3) << "frame " << i;
    EXPECT_NEAR(with.f0_filled[i], without.f0_filled[i], 0.5) << "frame " << i;
  }
  EXPECT_GT(voiced, 40);  // the tone is heard
  // The silence before it sits at the energy floor (was -26 dB with the offset).
  EXPECT_EQ(with.features(10, 1), kEnergyFloorDb);
}

TEST(DcOffset, AConstantSignalIsSilence) {
  Audio constant = test::silence(1.0, 24000);
  for (float& v : constant.samples) v = 0.5f;
  const FeatureTrack t = extract_features(constant, FeatureConfig{});
  ASSERT_GT(t.size(), 100u);
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_FALSE(t.raw[i].voiced) << "frame " << i;
    EXPECT_EQ(t.features(static_cast<Eigen::Index>(i), 1), kEnergyFloorDb) << "frame " << i;
  }
}

}  // namespace
}  // namespace animrt::head::dc_offset_test
