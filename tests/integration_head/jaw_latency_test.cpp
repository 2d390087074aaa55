// The jaw's lip-sync latency, end to end: a sound with bursts of voice at
// known sample times goes into the head of the bundled head robot, run in
// lockstep on its simulated Dynamixel servos, and the jaw's Goal Position is
// read back from the servo's own log of what arrived on its wire. Times are
// the simulated clock's, so the figures do not depend on the machine's load.
//   live sound (a file played as if captured): the jaw's first goal towards
//     open within 45 ms of each burst's first sample, never before it;
//   a recorded sound (looked ahead): within one cycle, never before it.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "animrt/controllers/head/audio.hpp"
#include "animrt/controllers/head/head_source.hpp"
#include "animrt/sim/dynamixel_sim_bus.hpp"
#include "support/sim_rig.hpp"

namespace animrt::jaw_test {
namespace {

const std::string kSrc = ANIMRT_SOURCE_DIR;
constexpr int kRate = 24000;
constexpr int kJawId = 4;
constexpr double kPeriodS = 0.01;  // the head robot's loop (100 Hz)

// Burst onsets (samples), at different phases of the 10 ms cycle and of the
// 10 ms audio block.
const std::vector<int> kOnsets = {7301, 19453, 31207};

std::string burst_file() {
  head::Audio a;
  a.sample_rate = kRate;
  a.samples.assign(static_cast<std::size_t>(kRate * 1.6), 0.0f);
  for (const int onset : kOnsets) {
    for (int i = 0; i < kRate / 5; ++i) {  // 0.2 s of a 180 Hz voiced sound
      a.samples[static_cast<std::size_t>(onset + i)] =
          0.3f * static_cast<float>(std::sin(2 * std::numbers::pi * 180.0 * i / kRate));
    }
  }
  const std::string path = ::testing::TempDir() + "/jaw_bursts.wav";
  head::write_wav(path, a);
  return path;
}

struct JawTiming {
  std::vector<double> lag_s;  // per burst: first goal towards open - onset
  bool moved_early = false;   // a goal left closed before a burst began
};

JawTiming measure(bool live) {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.2;
    for (BusConfig& b : c.buses) b.sim.wire_time = false;  // lockstep runs as fast as it can
  };
  const std::string wav = burst_file();
  settings.edit_motion = [&](LoadedRobot& r) {
    head::HeadMotionConfig c = *r.config.motion.head;
    c.audio = wav;
    c.audio_device = "none";
    c.repeat = false;
    c.live = live;
    r.motion = head::make_head_source(c, r.config.joints);
  };
  test::SimRig rig(kSrc + "/configs/robots/head.yaml", settings);
  Nanos motion_start = -1;
  RunOptions options = rig.options(1.8);
  options.on_motion_start = [&](Nanos start) { motion_start = start; };
  const RunSummary summary = rig.run(options);
  EXPECT_EQ(test::lockstep_problems(summary), "");
  EXPECT_GE(motion_start, 0);
  const auto log = dynamic_cast<sim::DynamixelSimBus&>(rig.sim("neck")).device_goal_log(kJawId);
  const double closed = rig.config().joints[3].home;  // the jaw's home is closed
  JawTiming timing;
  for (const int onset : kOnsets) {
    const Nanos at = motion_start + static_cast<Nanos>(std::llround(onset * 1e9 / kRate));
    const Nanos quiet_from = at - static_cast<Nanos>(0.1e9);  // the previous burst has closed
    double lag = 1e9;
    for (const sim::GoalRecord& g : log) {
      const bool open = g.rad > closed + deg_to_rad(0.05);
      if (g.time >= quiet_from && g.time < at && open) timing.moved_early = true;
      if (g.time >= at && open) {
        lag = to_seconds(g.time - at);
        break;
      }
    }
    timing.lag_s.push_back(lag);
  }
  return timing;
}

TEST(JawLatency, LiveSoundOpensTheJawWithin45msOnTheServosWire) {
  const JawTiming t = measure(true);
  EXPECT_FALSE(t.moved_early);
  for (std::size_t i = 0; i < t.lag_s.size(); ++i) EXPECT_LE(t.lag_s[i], 0.045) << "burst " << i;
}

TEST(JawLatency, RecordedSoundOpensTheJawWithinOneCycleNeverBefore) {
  const JawTiming t = measure(false);
  EXPECT_FALSE(t.moved_early);
  for (std::size_t i = 0; i < t.lag_s.size(); ++i) EXPECT_LT(t.lag_s[i], kPeriodS) << "burst " << i;
}

}  // namespace
}  // namespace animrt::jaw_test
