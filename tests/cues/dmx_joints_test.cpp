// DMX channels that drive joints, on a simulated clock: 8- and 16-bit levels
// map onto a joint's range; a lost stream holds, then eases back to the
// cues without a step; frames that come again ease over to them.

#include "animrt/controllers/cues/dmx_joints.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "animrt/controllers/cues/pose_source.hpp"

namespace animrt {
namespace {

std::vector<JointSpec> dmx_two_joints() {
  std::vector<JointSpec> joints(2);
  for (JointSpec& j : joints) {
    j.limits.min_position = -1.0;
    j.limits.max_position = 1.0;
    j.home = 0.1;
  }
  return joints;
}

// Cues that wind down at a stop (a walking cue): asked for the time it
// grants, and how long they take.
class WindsDown final : public MotionSource {
 public:
  std::span<const int> driven_joints() const override { return driven_; }
  void sample(double, std::span<double> targets) const override { targets[0] = 0.2; }
  double wind_down(double t, double granted_s) override {
    asked_at = t;
    granted = granted_s;
    return 0.75 * granted_s;
  }
  double asked_at = -1.0, granted = -1.0;

 private:
  std::vector<int> driven_{0};
};

// A stop under serve with DMX joints winds the cues down as without them.
TEST(DmxJoints, AStopWindsTheCuesDownUnderTheDmxJoints) {
  DmxJointInputs inputs({{1, 1, 0, -1.0, 1.0}});
  auto cues = std::make_unique<WindsDown>();
  WindsDown* inner = cues.get();
  DmxJointSource source(std::move(cues), inputs, dmx_two_joints(), 0.5);
  EXPECT_DOUBLE_EQ(source.wind_down(2.5, 1.2), 0.9);
  EXPECT_DOUBLE_EQ(inner->asked_at, 2.5);
  EXPECT_DOUBLE_EQ(inner->granted, 1.2);
}

TEST(DmxJoints, LevelsMapOntoTheRangeInEightAndSixteenBits) {
  DmxJointInputs inputs({{0, 1, 2, -1.0, 1.0}, {1, 3, 0, 0.0, 0.5}});
  std::vector<std::uint8_t> frame = {0x80, 0x00, 255};
  inputs.frame(frame);
  EXPECT_NEAR(inputs.target(0), -1.0 + 2.0 * 0x8000 / 65535.0, 1e-9);
  EXPECT_DOUBLE_EQ(inputs.target(1), 0.5);
  frame = {0xff, 0xff, 0};
  inputs.frame(frame);
  EXPECT_DOUBLE_EQ(inputs.target(0), 1.0);
  EXPECT_DOUBLE_EQ(inputs.target(1), 0.0);
  inputs.frame(std::vector<std::uint8_t>{0, 0});  // too short for joint 1: it keeps its level
  EXPECT_DOUBLE_EQ(inputs.target(0), -1.0);
  EXPECT_DOUBLE_EQ(inputs.target(1), 0.0);
  EXPECT_EQ(inputs.frames(), 3u);
}

TEST(DmxJoints, ALostStreamHoldsThenEasesBackToTheCuesWithoutAStep) {
  DmxJointInputs inputs({{1, 1, 0, -1.0, 1.0}});
  // The cues drive joint 0 only: joint 1 goes home without DMX.
  DmxJointSource source(make_pose_source({{0, 0.3}}), inputs, dmx_two_joints(), 0.5);
  ASSERT_EQ(source.driven_joints().size(), 2u);
  std::vector<double> targets(2, 0.0);
  const double dt = 0.01;
  double t = 0.0, last = 0.0, last_v = 0.0, max_a = 0.0;
  auto step = [&] {
    t += dt;
    source.sample(t, targets);
    const double v = (targets[1] - last) / dt;
    if (t > 2 * dt) max_a = std::max(max_a, std::abs(v - last_v) / dt);
    last_v = v;
    last = targets[1];
  };
  step();
  EXPECT_DOUBLE_EQ(targets[0], 0.3);
  EXPECT_DOUBLE_EQ(targets[1], 0.1);  // home: no frame yet
  // Frames at full for 2 s: eased over to +1.
  for (int i = 0; i < 200; ++i) {
    if (i % 4 == 0) inputs.frame(std::vector<std::uint8_t>{255});
    step();
  }
  EXPECT_DOUBLE_EQ(targets[1], 1.0);
  EXPECT_DOUBLE_EQ(targets[0], 0.3);
  // Silence: held for hold_s, then eased home within kDmxEaseS.
  for (int i = 0; i < 45; ++i) step();
  EXPECT_DOUBLE_EQ(targets[1], 1.0);
  EXPECT_EQ(source.losses(), 0u);
  for (int i = 0; i < 20; ++i) step();
  EXPECT_EQ(source.losses(), 1u);
  EXPECT_LT(targets[1], 1.0);
  EXPECT_GT(targets[1], 0.1);
  for (int i = 0; i < 110; ++i) step();
  EXPECT_DOUBLE_EQ(targets[1], 0.1);
  // The ease's own acceleration stays that of a 1 s quintic over the gap
  // (5.77 gap / T^2), nowhere near a jump's (gap / dt^2 = 9000).
  EXPECT_LT(max_a, 5.8 * 0.9 / (kDmxEaseS * kDmxEaseS));
}

}  // namespace
}  // namespace animrt
