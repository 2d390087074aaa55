#include "animrt/controllers/gait/balance_reflex.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace animrt {
namespace {

GaitBalance gains(double tilt_m, double tilt_rate_m_s) {
  GaitBalance b;
  b.tilt_m = tilt_m;
  b.tilt_rate_m_s = tilt_rate_m_s;
  return b;
}

constexpr BalanceLeg kFrontLeft{1.0, 1.0}, kFrontRight{1.0, -1.0}, kHindLeft{-1.0, 1.0},
    kHindRight{-1.0, -1.0};

TEST(BalanceReflex, NoseDownStretchesTheFrontLegsAndShortensTheHindOnes) {
  BalanceReflex reflex(gains(0.2, 0.0));
  // Nose down by sin = 0.1: the front end is down 0.1, the hind end up 0.1.
  reflex.update(TrunkTilt{-0.1, 0.0}, 0.002);
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontLeft, true), 0.02);
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontRight, true), 0.02);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindLeft, true), -0.02);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindRight, true), -0.02);
}

TEST(BalanceReflex, LeftSideDownStretchesTheLeftLegs) {
  BalanceReflex reflex(gains(0.2, 0.0));
  reflex.update(TrunkTilt{0.0, -0.05}, 0.002);  // rolled to the left
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontLeft, true), 0.01);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindLeft, true), 0.01);
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontRight, true), -0.01);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindRight, true), -0.01);
  // Roll and pitch add: front left is down on both counts.
  reflex.update(TrunkTilt{-0.05, -0.05}, 0.002);
  reflex.update(TrunkTilt{-0.05, -0.05}, 0.002);  // no rate
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontLeft, true), 0.02);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindRight, true), -0.02);
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontRight, true), 0.0);
}

TEST(BalanceReflex, ClampedToTheLongestStretch) {
  BalanceReflex reflex(gains(2.0, 0.0));
  reflex.update(TrunkTilt{-0.5, 0.0}, 0.002);  // asks 1 m
  EXPECT_DOUBLE_EQ(reflex.stretch(kFrontLeft, true), kMaxBalanceStretchM);
  EXPECT_DOUBLE_EQ(reflex.stretch(kHindLeft, true), -kMaxBalanceStretchM);
}

TEST(BalanceReflex, ALegInTheAirIsNotStretched) {
  BalanceReflex reflex(gains(0.2, 0.1));
  reflex.update(TrunkTilt{-0.1, -0.1}, 0.002);
  EXPECT_EQ(reflex.stretch(kFrontLeft, false), 0.0);
  EXPECT_NE(reflex.stretch(kFrontLeft, true), 0.0);
}

TEST(BalanceReflex, DampsTheRateOfTiltFromTheSecondStep) {
  BalanceReflex reflex(gains(0.0, 0.01));
  // The first step has no rate, whatever the tilt.
  reflex.update(TrunkTilt{0.0, 0.0}, 0.01);
  EXPECT_EQ(reflex.stretch(kFrontLeft, true), 0.0);
  // The nose drops 0.02 in 0.01 s: 2 /s down at the front, 0.02 m.
  reflex.update(TrunkTilt{-0.02, 0.0}, 0.01);
  EXPECT_NEAR(reflex.stretch(kFrontLeft, true), 0.02, 1e-15);
  EXPECT_NEAR(reflex.stretch(kHindLeft, true), -0.02, 1e-15);
  // Held there: no rate, no stretch.
  reflex.update(TrunkTilt{-0.02, 0.0}, 0.01);
  EXPECT_EQ(reflex.stretch(kFrontLeft, true), 0.0);
  // After a reset the next step is a first step again.
  reflex.reset();
  reflex.update(TrunkTilt{0.3, 0.0}, 0.01);
  EXPECT_EQ(reflex.stretch(kFrontLeft, true), 0.0);
}

TEST(BalanceReflex, StretchGoesToTheJointsLeastNorm) {
  // Joint 0 moves the foot 0.1 m down per rad, joint 1 0.2 m up per rad.
  const std::vector<double> down_per_rad{0.1, -0.2};
  std::vector<double> delta(2, 7.0);
  ASSERT_TRUE(leg_stretch_to_joints(0.01, down_per_rad, delta));
  // The foot goes down by exactly the stretch...
  EXPECT_NEAR(down_per_rad[0] * delta[0] + down_per_rad[1] * delta[1], 0.01, 1e-15);
  // ...along the Jacobian (least norm): 0.01 / 0.05 * (0.1, -0.2).
  EXPECT_NEAR(delta[0], 0.02, 1e-15);
  EXPECT_NEAR(delta[1], -0.04, 1e-15);
  // A leg whose joints cannot move the foot along the vertical is left alone.
  const std::vector<double> none{0.0, 0.0};
  std::vector<double> untouched(2, 7.0);
  EXPECT_FALSE(leg_stretch_to_joints(0.01, none, untouched));
  EXPECT_EQ(untouched, std::vector<double>(2, 7.0));
}

}  // namespace
}  // namespace animrt
