// A cue whose show has a sound track plays it when the cue is asked for, its
// motion on the sound's clock (a sound output whose crystal runs 0.4 % fast:
// without following, the motion would trail it by tens of milliseconds); a
// cue switch cuts the sound; a pause holds the sound where the motion comes
// to rest and resumes it in step. On a simulated clock, the player pumped
// by the test as its thread would be: no sound card, no waiting.

#include <gtest/gtest.h>
#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/cues/pose_source.hpp"
#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/runtime/cue_file.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "support/alloc_counter.hpp"

namespace animrt::cue_sound_test {
namespace {

constexpr int kRate = 8000;
constexpr double kFast = 1.004;

// An output that plays from its first write at `ratio` times the clock's
// rate and keeps everything it was given; a flush drops what was not heard.
class FastOutput final : public AudioSink {
 public:
  FastOutput(const Clock& clock, std::vector<float>& written) : clock_(clock), written_(written) {}
  std::int64_t queued_frames() override { return size() - base_ - played(); }
  void write(std::span<const float> mono) override {
    if (!started_) start_ = clock_.now();
    started_ = true;
    written_.insert(written_.end(), mono.begin(), mono.end());
  }
  void flush() override {
    written_.resize(static_cast<std::size_t>(base_ + played()));
    base_ = size();
    started_ = false;
  }
  // The sample heard now (0 before any).
  float heard() const {
    const std::int64_t at = base_ + played() - 1;
    return at >= 0 ? written_[static_cast<std::size_t>(at)] : 0.0f;
  }

 private:
  std::int64_t size() const { return static_cast<std::int64_t>(written_.size()); }
  std::int64_t played() const {
    if (!started_) return 0;
    const auto due =
        static_cast<std::int64_t>(std::floor(to_seconds(clock_.now() - start_) * kRate * kFast));
    return std::min(due, size() - base_);
  }

  const Clock& clock_;
  std::vector<float>& written_;
  bool started_ = false;
  Nanos start_ = 0;
  std::int64_t base_ = 0;
};

// One joint whose position in degrees is the show's time in seconds, and a
// track whose every sample is its own track frame + 1 (what is heard tells when).
ShowFile talk_show() {
  ShowFile show;
  show.file = "talk.yaml";
  show.duration_s = 30.0;
  show.has_audio = true;
  ShowTrack track;
  track.joint = "pan";
  for (double t : {0.0, 30.0}) {
    ShowKey key;
    key.t = t;
    key.value = t;
    key.interpolation = Interpolation::linear;
    track.keys.push_back(key);
  }
  show.tracks.push_back(track);
  return show;
}

// The figure: a rest pose (cue 0, idle) and the talking show (cue 1), the
// show's sound on a fast output, stepped every 10 ms.
struct Rig {
  const std::vector<JointSpec> joints{{"pan", {-60.0, 60.0, 10.0, 100.0}, 0.0}};
  ManualClock clock{from_seconds(1000.0)};
  Nanos t0 = clock.now();
  std::vector<float> written;
  FastOutput* out = nullptr;
  std::unique_ptr<ShowAudioPlayer> sound;
  CueRequests requests;
  std::unique_ptr<CuePlayer> cues;
  std::vector<double> pose = std::vector<double>(1, 0.0);
  long allocations = 0;  // by sample()

  Rig() {
    const ShowFile show = talk_show();
    AudioTrack track;
    track.rate = kRate;
    track.samples.resize(static_cast<std::size_t>(30 * kRate));
    for (std::size_t i = 0; i < track.samples.size(); ++i) track.samples[i] = float(i + 1);
    written.reserve(track.samples.size() * 2);
    auto output = std::make_unique<FastOutput>(clock, written);
    out = output.get();
    sound = std::make_unique<ShowAudioPlayer>(show, track, std::move(output), clock, false);
    std::vector<Cue> list(2);
    list[0].name = "rest";
    list[0].steps.push_back(CueStep{make_pose_source({{0, 0.0}})});
    list[1].name = "talk";
    list[1].crossfade_s = 0.5;
    list[1].steps.push_back(CueStep{make_show_source(show, joints), show.duration_s, show.file});
    cues = std::make_unique<CuePlayer>(std::move(list), 0, joints, requests);
    cues->play_sound(show.file, *sound);
  }
  // Cycle k: the sound's output kept 50 ms ahead, then the motion sampled.
  void step(int k) {
    const double t = k * 0.01;
    clock.set(t0 + from_seconds(t));
    const std::int64_t block = kRate / 100, capacity = 5 * block;
    if (k > 0) {
      while (out->queued_frames() <= capacity - block) ASSERT_TRUE(sound->pump());
    }
    const test::AllocationCounter counter;
    cues->sample(t, pose);  // the cycle's part: it tells the sound, never allocating
    allocations += counter.count();
    if (k == 0) {  // as the run does: started after the cycle that sampled t = 0
      cues->start(MotionClock{&clock, t0, true});
      sound->start(t0);
    }
  }
  double motion_s() const { return rad_to_deg(pose[0]); }
  // Track seconds heard now, or -1 for silence.
  double heard_s() const { return out->heard() > 0.0f ? (out->heard() - 1.0) / kRate : -1.0; }
};

TEST(CueSound, ACuePlaysItsSoundItsMotionOnTheSoundsClockAndASwitchCutsIt) {
  Rig rig;
  double max_gap = 0.0, min_step = 1.0, max_step = 0.0, last = 0.0;
  for (int k = 0; k <= 1500; ++k) {
    if (k == 100) rig.requests.cue(1);   // talk, at 1 s
    if (k == 1300) rig.requests.cue(0);  // rest, at 13 s
    rig.step(k);
    if (HasFatalFailure()) return;
    const double heard = rig.heard_s();
    if (k < 100) {
      ASSERT_LT(heard, 0.0) << "sound before the cue, at cycle " << k;
    } else if (k >= 300 && k < 1300) {
      // The crossfade (0.5 s) long over: the motion is the show, where it is heard.
      ASSERT_GE(heard, 0.0) << "no sound at cycle " << k;
      max_gap = std::max(max_gap, std::abs(rig.motion_s() - heard));
      if (k > 300) {
        min_step = std::min(min_step, rig.motion_s() - last);
        max_step = std::max(max_step, rig.motion_s() - last);
      }
    } else if (k >= 1310) {
      ASSERT_LT(heard, 0.0) << "the first cue's sound goes on after the switch, at cycle " << k;
    }
    last = rig.motion_s();
  }
  std::cout << "talking 12 s at +0.4 %: largest gap " << max_gap * 1e3
            << " ms; show time per 10 ms cycle " << min_step * 1e3 << ".." << max_step * 1e3
            << " ms\n";
  // 12 s at +0.4 % is 48 ms of drift unfollowed: followed, within one cycle.
  EXPECT_LT(max_gap, 0.01);
  EXPECT_GT(min_step, 0.01 * (1.0 - SoundFollower::kMaxRate) - 1e-9);
  EXPECT_LT(max_step, 0.01 * (1.0 + SoundFollower::kMaxRate) + 1e-9);
  EXPECT_EQ(rig.cues->sound_commands_lost(), 0u);
  EXPECT_EQ(rig.cues->starts(1), 1u);
  EXPECT_EQ(rig.allocations, 0);
}

TEST(CueSound, APauseHoldsTheSoundWhereTheMotionRestsAndResumesInStep) {
  Rig rig;
  double held_motion = -1.0, max_gap = 0.0, ramp_gap = 0.0;
  for (int k = 0; k <= 1400; ++k) {
    if (k == 100) rig.requests.cue(1);
    if (k == 600) rig.requests.pause(true);   // at 6 s
    if (k == 900) rig.requests.pause(false);  // at 9 s
    rig.step(k);
    if (HasFatalFailure()) return;
    const double heard = rig.heard_s();
    if (k >= 660 && k < 900) {
      // Eased to a halt (0.5 s): silent, the motion still.
      ASSERT_LT(heard, 0.0) << "sound during the pause, at cycle " << k;
      if (held_motion < 0.0) held_motion = rig.motion_s();
      ASSERT_NEAR(rig.motion_s(), held_motion, 1e-9);
    }
    if ((k >= 600 && k < 625) || (k >= 925 && k < 960)) {
      // Easing out and in, while the sound plays: apart by the easing's lag alone.
      if (heard >= 0.0) ramp_gap = std::max(ramp_gap, std::abs(rig.motion_s() - heard));
    }
    if (k >= 1100) max_gap = std::max(max_gap, std::abs(rig.motion_s() - heard));
  }
  std::cout << "pause: motion held at " << held_motion << " s; gap while easing " << ramp_gap * 1e3
            << " ms, after " << max_gap * 1e3 << " ms\n";
  EXPECT_GT(held_motion, 5.0);
  EXPECT_LT(ramp_gap, 0.045);  // the figure's mouth never leads it by more (ITU-R BT.1359)
  EXPECT_LT(max_gap, 0.01);
  EXPECT_EQ(rig.cues->sound_commands_lost(), 0u);
}

// The cue file tells which steps have a sound track to play.
TEST(CueSound, TheCueFileNamesTheShowsThatHaveASoundTrack) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / "cue_sound";
  fs::create_directories(dir);
  SF_INFO info{};
  info.samplerate = kRate;
  info.channels = 1;
  info.format = SF_FORMAT_WAV | SF_FORMAT_PCM_16;
  SNDFILE* f = sf_open((dir / "talk.wav").c_str(), SFM_WRITE, &info);
  const std::vector<short> frames(800, 1000);
  sf_writef_short(f, frames.data(), 800);
  sf_close(f);
  std::ofstream(dir / "talk.yaml") << "audio: {file: talk.wav}\njoints:\n  neck_pan: {keys: "
                                      "[[0, 0], [1, 10]]}\n";
  std::ofstream(dir / "mute.yaml") << "joints:\n  neck_pan: {keys: [[0, 0], [1, 10]]}\n";
  std::ofstream(dir / "cues.yaml")
      << "idle: rest\n"
         "cues:\n"
         "  rest: {play: {show: mute.yaml}}\n"
         "  talk: {play: [{show: talk.yaml}, {pose: {neck_pan: 5}}]}\n";
  const RobotConfig robot =
      load_robot_config(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml");
  const LoadedCues loaded = load_cues((dir / "cues.yaml").string(), robot);
  ASSERT_EQ(loaded.cues.size(), 2u);
  const int talk = find_cue(loaded.cues, "talk");
  const int rest = find_cue(loaded.cues, "rest");
  EXPECT_EQ(loaded.cues[rest].steps[0].show_file, "");
  EXPECT_EQ(fs::path(loaded.cues[talk].steps[0].show_file), dir / "talk.yaml");
  EXPECT_EQ(loaded.cues[talk].steps[1].show_file, "");
}

}  // namespace
}  // namespace animrt::cue_sound_test
