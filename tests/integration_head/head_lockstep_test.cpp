// A head streaming speech (playback: realtime) in a lockstep run moves with
// the simulated time alone: however fast or slowly the machine runs the
// cycles, the same targets at the same motion times.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "animrt/controllers/head/head_source.hpp"
#include "animrt/core/clock.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

const std::string kSrc = ANIMRT_SOURCE_DIR;

std::vector<JointSpec> head_joints() {
  std::vector<JointSpec> joints(4);
  const char* names[] = {"yaw", "pitch", "roll", "jaw"};
  for (std::size_t i = 0; i < 4; ++i) {
    joints[i].name = names[i];
    joints[i].limits = {deg_to_rad(-30), deg_to_rad(30), 1, 1};
  }
  return joints;
}

head::HeadMotionConfig streamed_head() {
  head::HeadMotionConfig c;
  c.model = kSrc + "/configs/head/model.txt";
  c.audio = kSrc + "/configs/head/utterance.wav";
  c.precomputed = false;  // streamed on a worker thread as the run's clock passes
  c.audio_device = "none";
  c.yaw.joint = "yaw";
  c.pitch.joint = "pitch";
  c.roll.joint = "roll";
  c.jaw.joint = "jaw";
  return c;
}

// Plays the head for `cycles` cycles of 10 ms on a lockstep clock, sleeping
// `pause(k)` of wall time before cycle k; the targets of every cycle.
template <typename Pause>
std::vector<double> play_lockstep(int cycles, Pause pause) {
  const std::vector<JointSpec> joints = head_joints();
  auto source = head::make_head_source(streamed_head(), joints);
  ManualClock clock;
  std::vector<double> targets(4, 0.0), out;
  constexpr Nanos kPeriod = 10'000'000;
  source->sample(0.0, targets);
  source->start(MotionClock{&clock, 0, true});
  for (int k = 0; k < cycles; ++k) {
    std::this_thread::sleep_for(pause(k));
    clock.set(k * kPeriod);
    source->sample(to_seconds(k * kPeriod), targets);
    out.insert(out.end(), targets.begin(), targets.end());
  }
  source->stop();
  return out;
}

TEST(HeadLockstep, TargetsDependOnTheRunsClockNotTheWallClock) {
  constexpr int kCycles = 300;  // 3 s: the head speaks for most of it
  const auto fast = play_lockstep(kCycles, [](int) { return std::chrono::microseconds(0); });
  // Slower than real time, with a stall: the wall clock runs far ahead.
  const auto slow = play_lockstep(kCycles, [](int k) {
    return std::chrono::microseconds(k == 40 ? 300'000 : (k % 3 == 0 ? 15'000 : 0));
  });
  ASSERT_EQ(fast.size(), slow.size());
  EXPECT_EQ(fast, slow);
  // And the head moved: each axis and the jaw over more than a degree.
  for (std::size_t j = 0; j < 4; ++j) {
    double lo = 1e9, hi = -1e9;
    for (std::size_t k = j; k < fast.size(); k += 4) {
      lo = std::min(lo, fast[k]);
      hi = std::max(hi, fast[k]);
    }
    EXPECT_GT(hi - lo, deg_to_rad(1.0)) << "joint " << j;
  }
}

TEST(HeadLockstep, StreamedPlaysAsPrecomputedOnTheSimulatedClock) {
  // The same stream run at load: within the first utterance (before the
  // precomputed stream is flushed at its end) the poses are the same.
  constexpr int kCycles = 200;
  const auto streamed = play_lockstep(kCycles, [](int) { return std::chrono::microseconds(0); });
  const std::vector<JointSpec> joints = head_joints();
  head::HeadMotionConfig c = streamed_head();
  c.precomputed = true;
  auto pre = head::make_head_source(c, joints);
  std::vector<double> targets(4, 0.0);
  for (int k = 0; k < kCycles; ++k) {
    pre->sample(to_seconds(k * Nanos{10'000'000}), targets);
    for (std::size_t j = 0; j < 4; ++j) {
      ASSERT_EQ(streamed[static_cast<std::size_t>(k) * 4 + j], targets[j])
          << "cycle " << k << " joint " << j;
    }
  }
}

// The runtime's lockstep run of the bundled head robot: once with the cycles
// as fast as the machine goes, once slower than real time; the commands are
// the same bit for bit.
TEST(HeadLockstep, RunnerRunsRepeatWhateverThePacing) {
  const std::string a = ::testing::TempDir() + "/head_lockstep_fast.csv";
  const std::string b = ::testing::TempDir() + "/head_lockstep_slow.csv";
  const std::string robot = kSrc + "/configs/robots/head.yaml";
  test::RigSettings settings;
  settings.edit_motion = [](LoadedRobot& r) {  // no sound card's pace
    head::HeadMotionConfig c = *r.config.motion.head;
    c.audio_device = "none";
    r.motion = head::make_head_source(c, r.config.joints);
  };
  RunSummary sa, sb;
  {
    test::SimRig rig(robot, settings);
    sa = rig.run(2.5, a);
  }
  {
    test::SimRig rig(robot, settings);
    rig.probe->on_sample = [](double) {
      std::this_thread::sleep_for(std::chrono::milliseconds(12));
    };
    sb = rig.run(2.5, b);
  }
  EXPECT_EQ(test::lockstep_problems(sa), "");
  EXPECT_EQ(test::lockstep_problems(sb), "");
  EXPECT_GT(sa.cycles, 250u);
  EXPECT_EQ(test::first_difference(a, b), "");
}

}  // namespace
}  // namespace animrt
