// A DC offset (a cheap microphone's) is no speech: silence with an offset
// leaves the jaw closed as plain silence does, a constant signal never opens
// it, and speech on top of the offset still opens it, for a sound file
// (looked ahead) and for live sound alike.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::jaw_dc_test {
namespace {

const std::string kSrc = ANIMRT_SOURCE_DIR;
constexpr int kRate = 24000;
constexpr Nanos kPeriod = 10'000'000;  // 100 Hz cycles

// `silence_s` of silence, then `voice_s` of a 180 Hz voiced sound, all
// shifted by `dc`.
std::string write_sound(const std::string& name, double silence_s, double voice_s, float dc) {
  head::Audio a;
  a.sample_rate = kRate;
  const auto quiet = static_cast<std::size_t>(silence_s * kRate);
  a.samples.assign(quiet + static_cast<std::size_t>(voice_s * kRate), dc);
  for (std::size_t i = quiet; i < a.samples.size(); ++i) {
    const double t = static_cast<double>(i - quiet) / kRate;
    a.samples[i] += 0.3f * static_cast<float>(std::sin(2 * std::numbers::pi * 180.0 * t));
  }
  const std::string path = ::testing::TempDir() + "/" + name + ".wav";
  head::write_wav(path, a);
  return path;
}

std::unique_ptr<MotionSource> jaw_only_head(const std::string& wav, bool live) {
  head::HeadMotionConfig c;
  c.model = kSrc + "/configs/head/model.txt";
  c.audio = wav;
  c.audio_device = "none";
  c.repeat = false;
  c.live = live;
  c.precomputed = !live;  // a file's jaw needs no worker; live sound is fed by one
  c.jaw.joint = "jaw";
  std::vector<JointSpec> joints(1);
  joints[0].name = "jaw";
  joints[0].limits = {deg_to_rad(0), deg_to_rad(30), 1, 1};
  return head::make_head_source(c, joints);
}

// The jaw's angle (deg) at every cycle of `seconds`, on a lockstep clock.
std::vector<double> jaw_track(const std::string& wav, bool live, double seconds) {
  auto source = jaw_only_head(wav, live);
  ManualClock clock;
  std::vector<double> targets(1, 0.0), jaw;
  source->start(MotionClock{&clock, 0, true});
  const auto cycles = static_cast<int>(std::lround(seconds * 1e9 / kPeriod));
  for (int k = 0; k < cycles; ++k) {
    clock.set(k * kPeriod);
    source->sample(to_seconds(k * kPeriod), targets);
    jaw.push_back(rad_to_deg(targets[0]));
  }
  source->stop();
  return jaw;
}

double max_between(const std::vector<double>& track, double from_s, double to_s) {
  double most = -1e9;
  for (auto k = static_cast<std::size_t>(from_s * 100); k < static_cast<std::size_t>(to_s * 100);
       ++k)
    most = std::max(most, track.at(k));
  return most;
}

TEST(JawDcOffset, SilenceWithAnOffsetKeepsTheJawClosedAndSpeechStillOpensIt) {
  const std::string plain = write_sound("jaw_dc_plain", 1.0, 0.5, 0.0f);
  const std::string offset = write_sound("jaw_dc_offset", 1.0, 0.5, 0.05f);
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "file");
    const std::vector<double> without = jaw_track(plain, live, 1.5);
    const std::vector<double> with = jaw_track(offset, live, 1.5);
    EXPECT_EQ(max_between(without, 0.05, 0.95), 0.0);
    EXPECT_EQ(max_between(with, 0.05, 0.95), 0.0);  // was 7.3 deg
    // The voice (RMS 0.21, above energy_full) opens the jaw fully either way.
    EXPECT_NEAR(max_between(without, 1.1, 1.5), 20.0, 1e-6);
    EXPECT_NEAR(max_between(with, 1.1, 1.5), 20.0, 1e-6);
  }
}

TEST(JawDcOffset, AConstantSignalDoesNotOpenTheJaw) {
  const std::string constant = write_sound("jaw_dc_constant", 1.0, 0.0, 0.5f);
  for (const bool live : {false, true}) {
    SCOPED_TRACE(live ? "live" : "file");
    EXPECT_EQ(max_between(jaw_track(constant, live, 1.0), 0.05, 0.95), 0.0);  // was fully open
  }
}

}  // namespace
}  // namespace animrt::jaw_dc_test
