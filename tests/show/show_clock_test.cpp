// A show's motion runs on its sound's clock: a sound output whose crystal
// runs 0.1 % fast plays a 10-minute show on a simulated clock beside the
// show's motion, and at every cycle the motion is where the sound is heard
// (within one 10 ms cycle), the sound never skips and the motion never
// jumps, also across a seek. No sound card, no waiting: the player is
// pumped by the test as its thread would be.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <vector>

#include "animrt/controllers/show/show_audio.hpp"
#include "animrt/controllers/show/show_file.hpp"
#include "animrt/controllers/show/sound_clock.hpp"

namespace animrt {
namespace {

constexpr int kRate = 8000;

// An output that plays from its first write at `ratio` times the loop
// clock's rate, keeps everything it was given (`written`), and holds
// `capacity` frames.
class DriftingOutput final : public AudioSink {
 public:
  DriftingOutput(const Clock& clock, double ratio, std::vector<float>& written)
      : clock_(clock), ratio_(ratio), written_(written) {}
  std::int64_t queued_frames() override { return size() - base_ - played(); }
  void write(std::span<const float> mono) override {
    if (!started_) start_ = clock_.now();
    started_ = true;
    written_.insert(written_.end(), mono.begin(), mono.end());
  }
  void flush() override {
    // What was not heard is dropped; the output starts again at the next write.
    written_.resize(static_cast<std::size_t>(base_ + played()));
    base_ = size();
    started_ = false;
  }
  // The index in `written` of the sample at the output now, -1 before any.
  std::int64_t now_index() const { return base_ + played() - 1; }

 private:
  std::int64_t size() const { return static_cast<std::int64_t>(written_.size()); }
  std::int64_t played() const {
    if (!started_) return 0;
    const auto due =
        static_cast<std::int64_t>(std::floor(to_seconds(clock_.now() - start_) * kRate * ratio_));
    return std::min(due, size() - base_);  // an underrun waits for the next write
  }

  const Clock& clock_;
  double ratio_;
  std::vector<float>& written_;
  bool started_ = false;
  Nanos start_ = 0;
  std::int64_t base_ = 0;  // `written` index of the first frame since the last flush
};

ShowFile ramp_show(double duration_s) {
  // One joint whose position in degrees is the show's time in seconds.
  ShowFile show;
  show.file = "clock_show.yaml";
  show.duration_s = duration_s;
  show.has_audio = true;
  ShowTrack track;
  track.joint = "pan";
  for (double t : {0.0, duration_s}) {
    ShowKey key;
    key.t = t;
    key.value = t;
    key.interpolation = Interpolation::linear;
    track.keys.push_back(key);
  }
  show.tracks.push_back(track);
  return show;
}

TEST(ShowClock, ATenMinuteShowEndsInStepWithASoundOutputThatRunsFast) {
  const ShowFile show = ramp_show(700.0);
  AudioTrack track;  // each sample is its own track frame + 1: what is heard tells when
  track.rate = kRate;
  track.samples.resize(static_cast<std::size_t>(700 * kRate));
  for (std::size_t i = 0; i < track.samples.size(); ++i) track.samples[i] = float(i + 1);
  const std::vector<JointSpec> joints{{"pan", {-20.0, 20.0, 10.0, 100.0}, 0.0}};
  const auto motion = make_show_source(show, joints);

  ManualClock clock(from_seconds(1000.0));
  std::vector<float> written;
  written.reserve(track.samples.size());
  auto output = std::make_unique<DriftingOutput>(clock, 1.001, written);
  DriftingOutput& out = *output;
  ShowAudioPlayer player(show, track, std::move(output), clock, false);
  motion->follow_sound(show.file, player.sound_clock());
  const Nanos t0 = clock.now();
  player.start(t0);
  motion->start(MotionClock{&clock, t0, true});

  std::vector<double> pose(1, 0.0);
  double last_show = 0.0, max_gap = 0.0, end_gap = 0.0, min_step = 1.0, max_step = 0.0;
  const std::int64_t block = kRate / 100, capacity = 5 * block;  // 50 ms of buffer
  for (int k = 0; k <= 60000; ++k) {
    const double t = k * 0.01;
    clock.set(t0 + from_seconds(t));
    if (k == 30000) {
      // A seek at 5 minutes, to 100 s: the show's and the sound's at once.
      const ShowCommand seek{true, 1, 100.0};
      motion->control(seek, t);
      ASSERT_TRUE(player.control(seek, t));
    }
    while (out.queued_frames() <= capacity - block) ASSERT_TRUE(player.pump());
    motion->sample(t, pose);
    const double show_s = rad_to_deg(pose[0]);
    const std::int64_t at = out.now_index();
    if (k == 0) continue;  // nothing heard yet
    ASSERT_GE(at, 0);
    const double heard_s = (written[static_cast<std::size_t>(at)] - 1.0) / kRate;
    if (k >= 100 && k != 30000) {  // after the first second; the seek is a jump
      min_step = std::min(min_step, show_s - last_show);
      max_step = std::max(max_step, show_s - last_show);
    }
    if (k >= 1000 && (k < 30000 || k >= 31000))
      max_gap = std::max(max_gap, std::abs(show_s - heard_s));
    end_gap = show_s - heard_s;
    last_show = show_s;
  }
  std::cout << "10 min at +0.1 %: gap at the end " << end_gap * 1e3 << " ms, largest "
            << max_gap * 1e3 << " ms; show time per 10 ms cycle " << min_step * 1e3 << ".."
            << max_step * 1e3 << " ms\n";
  EXPECT_LT(std::abs(end_gap), 0.01);  // one cycle
  EXPECT_LT(max_gap, 0.01);
  // The motion's speed changes by at most the follower's bound: no jump.
  EXPECT_GT(min_step, 0.01 * (1.0 - SoundFollower::kMaxRate) - 1e-9);
  EXPECT_LT(max_step, 0.01 * (1.0 + SoundFollower::kMaxRate) + 1e-9);
  // The sound never skipped: every sample follows the one before, but at the seek.
  int jumps = 0;
  for (std::size_t i = 1; i < written.size(); ++i) jumps += written[i] != written[i - 1] + 1.0f;
  EXPECT_EQ(jumps, 1);
}

}  // namespace
}  // namespace animrt
