#include "animrt/runtime/safety_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "animrt/runtime/pose_ramp.hpp"

namespace animrt {
namespace {

constexpr double kDt = 0.005;
const JointLimits kLimits{-1.0, 1.0, 3.0, 40.0};
constexpr double kTol = 1e-9;

// Runs the filter on a target sequence and checks every property on every
// cycle: within position limits, velocity limit, acceleration limit.
struct Checker {
  SafetyFilter filter;
  std::vector<double> command{0.0};
  double last_p;
  double last_v = 0.0;
  double max_step = 0.0;

  explicit Checker(double start, JointLimits limits = kLimits)
      : filter({limits}, kDt), last_p(start) {
    filter.reset(std::vector<double>{start});
  }

  void step(double target, const JointLimits& lim = kLimits) {
    std::vector<double> t{target};
    filter.step(t, command);
    const double p = command[0];
    const double v = (p - last_p) / kDt;
    const bool was_inside = last_p >= lim.min_position - kTol && last_p <= lim.max_position + kTol;
    if (was_inside) {
      ASSERT_LE(p, lim.max_position + kTol);
      ASSERT_GE(p, lim.min_position - kTol);
    }
    ASSERT_LE(std::abs(v), lim.max_velocity * (1 + 1e-9) + kTol);
    ASSERT_LE(std::abs(v - last_v), lim.max_acceleration * kDt * (1 + 1e-9) + kTol);
    max_step = std::max(max_step, std::abs(p - last_p));
    last_p = p;
    last_v = v;
  }
};

TEST(SafetyFilter, StoppingSpeedBrakesExactlyOntoTheLimit) {
  const double a = 40.0 * kDt;
  for (int n = 1; n < 20; ++n) {
    const double distance = kDt * a * n * (n + 1) / 2.0;
    EXPECT_NEAR(stopping_speed(distance, a, kDt), n * a, 1e-9);
    // and never more than the distance itself in one cycle
    EXPECT_LE(stopping_speed(distance * 0.3, a, kDt) * kDt, distance * 0.3 + 1e-15);
  }
  EXPECT_EQ(stopping_speed(0.0, a, kDt), 0.0);
  EXPECT_EQ(stopping_speed(-1.0, a, kDt), 0.0);
}

TEST(SafetyFilter, StepTargetsNeverBreakAnyLimit) {
  Checker c(0.0);
  const double targets[] = {5.0, -5.0, 0.3, 0.31, -0.9, 1.0, -1.0, 0.0};
  for (double target : targets) {
    for (int i = 0; i < 400; ++i) c.step(target);
  }
  // and it does arrive at a reachable target
  for (int i = 0; i < 400; ++i) c.step(0.42);
  EXPECT_NEAR(c.command[0], 0.42, 1e-9);
}

TEST(SafetyFilter, RandomTargetsNeverBreakAnyLimit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> target(-2.0, 2.0);
  std::uniform_int_distribution<int> hold(1, 60);
  Checker c(0.0);
  for (int segment = 0; segment < 500; ++segment) {
    const double t = target(rng);
    const int cycles = hold(rng);
    for (int i = 0; i < cycles; ++i) c.step(t);
  }
}

TEST(SafetyFilter, TracksASmoothMotionWithinLimitsWithoutLag) {
  Checker c(0.0);
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double t = k * kDt;
    const double target = 0.5 * std::sin(2 * M_PI * 0.8 * t);  // 2.5 rad/s, 12.6 rad/s^2 peak
    c.step(target);
    if (k > 400) worst = std::max(worst, std::abs(c.command[0] - target));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(SafetyFilter, AJumpInTheTargetIsNotAJumpInTheCommand) {
  // Tracking a motion, then the target jumps to home (as at a fault or stop).
  Checker c(0.0);
  for (int k = 0; k < 300; ++k) c.step(0.8 * std::sin(2 * M_PI * 0.5 * k * kDt));
  for (int k = 0; k < 600; ++k) c.step(-0.7);
  EXPECT_LE(c.max_step, kLimits.max_velocity * kDt + 1e-12);
  EXPECT_NEAR(c.command[0], -0.7, 1e-9);
}

TEST(SafetyFilter, StartOutsideTheLimitsComesBackGently) {
  Checker c(1.3);
  for (int k = 0; k < 600; ++k) {
    c.step(0.0);
    ASSERT_LE(c.command[0], 1.3 + kTol);  // never further out
  }
  EXPECT_NEAR(c.command[0], 0.0, 1e-9);
}

TEST(SafetyFilter, HandlesManyJointsIndependently) {
  std::vector<JointLimits> limits{kLimits, JointLimits{-0.5, 0.5, 1.0, 10.0}};
  SafetyFilter filter(limits, kDt);
  filter.reset(std::vector<double>{0.0, 0.0});
  std::vector<double> targets{0.9, 3.0}, commands(2);
  for (int k = 0; k < 2000; ++k) filter.step(targets, commands);
  EXPECT_NEAR(commands[0], 0.9, 1e-9);
  EXPECT_NEAR(commands[1], 0.5, 1e-9);  // clamped to its own limit
}

TEST(PoseRamp, StartsAndEndsAtRestAndRespectsLimits) {
  std::vector<JointLimits> limits{kLimits, kLimits};
  PoseRamp ramp(2);
  std::vector<double> from{-0.9, 0.1}, to{0.9, 0.1};
  ramp.plan(from, to, limits, 0.5);
  // 1.8 rad at 3 rad/s peak needs at least 1.875*1.8/3 s
  EXPECT_GE(ramp.duration(), 1.875 * 1.8 / 3.0);
  std::vector<double> pose(2), previous(from);
  double previous_v = 0.0;
  for (double t = 0.0; t <= ramp.duration() + 0.1; t += kDt) {
    ramp.sample(t, pose);
    const double v = (pose[0] - previous[0]) / kDt;
    EXPECT_LE(std::abs(v), kLimits.max_velocity);
    EXPECT_LE(std::abs(v - previous_v) / kDt, kLimits.max_acceleration * 1.05);
    EXPECT_DOUBLE_EQ(pose[1], 0.1);
    previous = pose;
    previous_v = v;
  }
  EXPECT_DOUBLE_EQ(pose[0], 0.9);
  ramp.sample(0.0, pose);
  EXPECT_DOUBLE_EQ(pose[0], -0.9);
}

TEST(PoseRamp, KeepsTheMinimumDurationForShortMoves) {
  std::vector<JointLimits> limits{kLimits};
  PoseRamp ramp(1);
  ramp.plan(std::vector<double>{0.0}, std::vector<double>{0.01}, limits, 2.0);
  EXPECT_DOUBLE_EQ(ramp.duration(), 2.0);
}

TEST(SafetyFilter, NonFiniteTargetsHoldTheJointAndNeverReachTheState) {
  SafetyFilter filter({kLimits, kLimits}, kDt);
  filter.reset(std::vector<double>{0.2, 0.2});
  std::vector<double> command(2);
  for (int i = 0; i < 20; ++i) filter.step(std::vector<double>{0.8, 0.8}, command);
  const double held = command[0];
  const double bad[] = {std::nan(""), INFINITY, -INFINITY};
  for (double b : bad) {
    filter.step(std::vector<double>{b, 0.8}, command);
    EXPECT_EQ(command[0], held);
    EXPECT_TRUE(std::isfinite(filter.position()[0]));
    EXPECT_EQ(filter.velocity()[0], 0.0);
  }
  EXPECT_GT(command[1], held);  // the other joint went on
}

TEST(SafetyFilter, AnInactiveJointHoldsAndResumesFromRest) {
  SafetyFilter filter({kLimits}, kDt);
  filter.reset(std::vector<double>{0.0});
  std::vector<double> command(1);
  const std::vector<std::uint8_t> on{1}, off{0};
  double t = 0.0;
  for (int i = 0; i < 50; ++i, t += kDt)
    filter.step(std::vector<double>{0.9 * std::sin(4 * t)}, command, on);
  const double held = command[0];
  for (int i = 0; i < 10; ++i, t += kDt) {
    filter.step(std::vector<double>{0.9 * std::sin(4 * t)}, command, off);
    EXPECT_EQ(command[0], held);
  }
  filter.step(std::vector<double>{0.9 * std::sin(4 * t)}, command, on);
  // From rest, the first move is at most one acceleration step.
  EXPECT_LE(std::abs(command[0] - held), kLimits.max_acceleration * kDt * kDt + kTol);
}

}  // namespace
}  // namespace animrt
