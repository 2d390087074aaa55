// A gait with its balance reflex as the runtime plays it: the IMU's attitude
// through sense(), the stretch through the figure's legs.

#include "animrt/controllers/gait/balanced_gait_source.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <vector>

namespace animrt {
namespace {

// Joint 0 at 0.1 rad, joint 1 at 0.2 rad, always.
class StillGait final : public MotionSource {
 public:
  std::span<const int> driven_joints() const override { return joints_; }
  void sample(double /*t*/, std::span<double> targets) const override {
    targets[0] = 0.1;
    targets[1] = 0.2;
  }

 private:
  std::vector<int> joints_{0, 1};
};

// A front leg on joint 0 and a hind leg on joint 1, both on the ground, each
// moving its foot 0.5 m down the trunk's vertical per radian.
class TwoLegs final : public LegModel {
 public:
  std::size_t leg_count() const override { return 2; }
  BalanceLeg where(std::size_t leg) const override {
    return leg == 0 ? BalanceLeg{1.0, 1.0} : BalanceLeg{-1.0, 1.0};
  }
  std::span<const int> joints(std::size_t leg) const override {
    return std::span<const int>(&joint_[leg], 1);
  }
  void pose(std::span<const double> positions, const std::array<double, 4>& trunk) override {
    posed.assign(positions.begin(), positions.end());
    trunk_quat = trunk;
  }
  bool on_ground(std::size_t /*leg*/) const override { return true; }
  void down_per_rad(std::size_t /*leg*/, std::span<double> out) override { out[0] = 0.5; }
  std::size_t max_leg_joints() const override { return 1; }

  std::vector<double> posed;
  std::array<double, 4> trunk_quat{};

 private:
  std::array<int, 2> joint_{0, 1};
};

GaitBalance gains() {
  GaitBalance b;
  b.tilt_m = 0.3;
  b.tilt_rate_m_s = 0.1;
  return b;
}

ImuReading pitched(double pitch, double time_s) {
  ImuReading r;
  r.quat = quat_from_ypr(0.0, pitch, 0.0);
  r.time_s = time_s;
  return r;
}

std::array<double, 2> sampled(const BalancedGaitSource& source) {
  std::array<double, 2> targets{};
  source.sample(1.0, targets);
  return targets;
}

class BalancedGaitSourceTest : public ::testing::Test {
 protected:
  BalancedGaitSourceTest() : source_(std::make_unique<StillGait>(), gains(), 2) {
    auto legs = std::make_unique<TwoLegs>();
    legs_ = legs.get();
    source_.attach(std::move(legs));
  }
  void sense(const ImuReading* reading) { source_.sense(Sensors{reading, {}}); }

  BalancedGaitSource source_;
  TwoLegs* legs_ = nullptr;
};

TEST_F(BalancedGaitSourceTest, NoseDownStretchesTheFrontLegAndShortensTheHindOne) {
  // Before any reading the curves play as they are.
  EXPECT_EQ(sampled(source_), (std::array<double, 2>{0.1, 0.2}));
  const ImuReading r = pitched(0.1, 0.01);  // nose down by sin(0.1)
  sense(&r);
  // stretch = 0.3 m * sin(0.1) (no rate on the first reading); the joint
  // change that makes it is stretch * 0.5 / 0.5^2.
  const double stretch = 0.3 * std::sin(0.1);
  const auto t = sampled(source_);
  EXPECT_NEAR(t[0], 0.1 + 2.0 * stretch, 1e-12);
  EXPECT_NEAR(t[1], 0.2 - 2.0 * stretch, 1e-12);
  // The legs were posed at the curves' targets with the IMU's attitude.
  EXPECT_EQ(legs_->posed, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(legs_->trunk_quat, r.quat);
}

// Where the cycle measured the joints, the legs are posed there: the physics
// the fitness walk reads is where the joints are, not where they were sent.
TEST_F(BalancedGaitSourceTest, TheLegsArePosedWhereTheJointsWereMeasured) {
  const ImuReading r = pitched(0.1, 0.01);
  const std::array<double, 2> measured{0.15, 0.25};
  source_.sense(Sensors{&r, measured});
  (void)sampled(source_);
  EXPECT_EQ(legs_->posed, (std::vector<double>{0.15, 0.25}));
}

TEST_F(BalancedGaitSourceTest, TheTiltRateIsTakenBetweenNewReadingsOnly) {
  const ImuReading a = pitched(0.1, 0.01);
  sense(&a);
  sense(&a);  // the same reading handed again: no new rate
  const ImuReading b = pitched(0.101, 0.02);
  sense(&b);
  sense(&b);
  const double rate = (std::sin(0.101) - std::sin(0.1)) / 0.01;
  const double stretch = 0.3 * std::sin(0.101) + 0.1 * rate;
  EXPECT_NEAR(sampled(source_)[0], 0.1 + 2.0 * stretch, 1e-9);
  EXPECT_EQ(source_.readings(), 2u);
}

TEST_F(BalancedGaitSourceTest, ASilentImuHoldsTheReflexWithoutAJump) {
  const ImuReading a = pitched(0.1, 0.01);
  sense(&a);
  const ImuReading b = pitched(0.101, 0.02);
  sense(&b);
  const auto before = sampled(source_);
  sense(nullptr);
  sense(nullptr);
  EXPECT_EQ(sampled(source_), before);
  EXPECT_EQ(source_.held_cycles(), 2u);
  // Back: the rate is taken over the whole gap.
  const ImuReading c = pitched(0.11, 0.05);
  sense(&c);
  const double stretch = 0.3 * std::sin(0.11) + 0.1 * (std::sin(0.11) - std::sin(0.101)) / 0.03;
  EXPECT_NEAR(sampled(source_)[0], 0.1 + 2.0 * stretch, 1e-9);
}

TEST(BalancedGaitSource, WithoutLegsTheCurvesPlayAsTheyAre) {
  BalancedGaitSource source(std::make_unique<StillGait>(), gains(), 2);
  EXPECT_FALSE(source.has_legs());
  const ImuReading r = pitched(0.1, 0.01);
  source.sense(Sensors{&r, {}});
  EXPECT_EQ(sampled(source), (std::array<double, 2>{0.1, 0.2}));
}

}  // namespace
}  // namespace animrt
