// A stop of a walking cue: the player hands the wind-down to what it plays,
// on that motion's own time, so the walk eases to a stand exactly as the
// gait does when it is the run's motion. A paused cue stands already.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "animrt/controllers/cues/cue_player.hpp"
#include "animrt/controllers/cues/pose_source.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/robot_loader.hpp"

namespace animrt {
namespace {

// More time than any wind-down asks for: the stop deadline does not cut it.
constexpr double kCueAmpleS = 100.0;

const std::string kWindRoot = ANIMRT_SOURCE_DIR;

// The quadruped's walk (a steered gait at its own speed) and a pose, each a
// cue; a second walk of the same file plays alone as the reference, from
// the cycle the player's walk starts at, so both see the same times.
struct WalkCues {
  RobotConfig robot = load_robot_config(kWindRoot + "/configs/robots/quadruped.yaml");
  double dt = 1.0 / robot.rate_hz;
  CueRequests requests;
  std::unique_ptr<MotionSource> reference = walk();
  std::unique_ptr<CuePlayer> player;
  std::vector<double> home;
  int next = 0;                        // the next cycle
  int walk_from = 0;                   // the cycle the reference starts at
  std::vector<double> pose, expected;  // the last cycle's: the player's, the reference's

  // `idle`: 0 the walk, 1 the pose. `fade_s`: the crossfade into each cue.
  explicit WalkCues(int idle, double fade_s = 1.0) {
    std::vector<Cue> cues(2);
    cues[0].name = "walk";
    cues[0].steps.push_back({walk(), kForever});
    cues[1].name = "stand";
    cues[1].steps.push_back({make_pose_source({{0, 0.1}, {1, -0.1}}), kForever});
    cues[0].crossfade_s = cues[1].crossfade_s = fade_s;
    for (const JointSpec& joint : robot.joints) home.push_back(joint.home);
    player = std::make_unique<CuePlayer>(std::move(cues), idle, robot.joints, requests);
  }
  std::unique_ptr<MotionSource> walk() const {
    MotionConfig motion;
    motion.type = "gait";
    motion.file = kWindRoot + "/configs/gaits/walk.yaml";
    return load_motion_source(motion, robot);
  }
  void cycle() {
    pose = expected = home;
    player->sample(next * dt, pose);
    if (next >= walk_from) reference->sample((next - walk_from) * dt, expected);
    ++next;
  }
  void play_to(int k) {
    while (next < k) cycle();
  }
  // The largest gap of any driven joint between the player and the reference.
  double gap() const {
    double most = 0.0;
    for (int j : player->driven_joints()) {
      const auto k = static_cast<std::size_t>(j);
      most = std::max(most, std::abs(pose[k] - expected[k]));
    }
    return most;
  }
};

TEST(CueWindDown, AWalkingCueWindsDownAsItsGaitDoes) {
  WalkCues f(0);
  const int k = 263;  // mid-stride
  f.play_to(k);
  const double asked = f.player->wind_down(k * f.dt, kCueAmpleS);
  const double own = f.reference->wind_down(k * f.dt, kCueAmpleS);
  ASSERT_GT(own, 1.0);
  EXPECT_DOUBLE_EQ(asked, own);
  // A cue asked for while it winds down waits: the walk goes on to rest.
  f.requests.cue(1);
  const auto j = static_cast<std::size_t>(f.player->driven_joints()[0]);
  std::vector<double> trace;
  while ((f.next - k) * f.dt <= own + 0.5) {
    f.cycle();
    ASSERT_LT(f.gap(), 1e-9) << "at " << (f.next - 1) * f.dt;
    trace.push_back(f.pose[j]);
  }
  EXPECT_EQ(f.player->current_cue(), 0);
  // It stepped on at first, then came to stand (the last 0.5 s stand still).
  const double stand = trace.back();
  double first_swing = 0.0, last_swing = 0.0, middle = 0.0;  // its first and last quarters
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const double t = static_cast<double>(i) * f.dt;
    double& swing = t < 0.25 * own ? first_swing : t > 0.75 * own ? last_swing : middle;
    swing = std::max(swing, std::abs(trace[i] - stand));
    if (t > own + f.dt) {
      EXPECT_NEAR(trace[i], stand, 1e-9) << t;
    }
  }
  EXPECT_GT(first_swing, 1e-2);
  EXPECT_LT(last_swing, 0.3 * first_swing);
}

// A stop that grants the walking cue less than its own wind-down: the
// player hands the grant on, and the walk stands, as the gait alone does,
// when the granted time is up.
TEST(CueWindDown, AWalkingCueStandsWithinTheTimeGranted) {
  WalkCues f(0);
  const int k = 263;
  f.play_to(k);
  const double own = WalkCues(0).reference->wind_down(k * f.dt, kCueAmpleS);
  const double granted = 0.4 * own;
  const double asked = f.player->wind_down(k * f.dt, granted);
  EXPECT_DOUBLE_EQ(asked, f.reference->wind_down(k * f.dt, granted));
  EXPECT_LE(asked, granted);
  std::vector<double> stood;
  while ((f.next - k) * f.dt <= granted + 0.5) {
    f.cycle();
    ASSERT_LT(f.gap(), 1e-9) << "at " << (f.next - 1) * f.dt;
    if ((f.next - 1 - k) * f.dt >= granted) {
      if (stood.empty()) stood = f.pose;
      for (int j : f.player->driven_joints()) {
        const auto i = static_cast<std::size_t>(j);
        ASSERT_NEAR(f.pose[i], stood[i], 1e-9) << "joint " << j << " at " << (f.next - 1) * f.dt;
      }
    }
  }
  EXPECT_FALSE(stood.empty());
}

// Mid-crossfade from a pose into the walk: both motions are asked, the stop
// waits for the walk, and the fade completes into the wound-down walk.
TEST(CueWindDown, ACrossfadeWaitsForTheLongerMotion) {
  WalkCues f(1, 0.5);
  const int asked_at = 100;
  f.walk_from = asked_at;
  f.play_to(asked_at);
  f.requests.cue(0);
  f.play_to(asked_at + 40);
  const double fade = f.player->last_crossfade_s();
  ASSERT_GT(fade, 40 * f.dt);
  const double asked = f.player->wind_down(f.next * f.dt, kCueAmpleS);
  const double own = f.reference->wind_down(40 * f.dt, kCueAmpleS);
  EXPECT_DOUBLE_EQ(asked, own);
  ASSERT_LT(fade, own);
  while ((f.next - asked_at) * f.dt < own) {
    f.cycle();
    if ((f.next - asked_at) * f.dt > fade + f.dt) {
      ASSERT_LT(f.gap(), 1e-9) << f.next;
    }
  }
}

TEST(CueWindDown, APausedCueStandsAlreadyAndAPausingOneEasesToRest) {
  WalkCues f(0);
  f.play_to(200);
  f.requests.pause(true);
  f.play_to(240);  // 0.2 s into the 0.5 s easing
  WalkCues g(0);
  g.play_to(200);
  g.requests.pause(true);
  g.play_to(400);
  // The pause was first seen at cycle 200, over the step from cycle 199.
  EXPECT_NEAR(f.player->wind_down(240 * f.dt, kCueAmpleS), kPauseRampS - 41 * f.dt, 1e-9);
  EXPECT_EQ(g.player->wind_down(400 * g.dt, kCueAmpleS), 0.0);
}

TEST(CueWindDown, APoseCueAsksForNothing) {
  WalkCues f(1);
  f.play_to(100);
  EXPECT_EQ(f.player->wind_down(100 * f.dt, kCueAmpleS), 0.0);
}

}  // namespace
}  // namespace animrt
