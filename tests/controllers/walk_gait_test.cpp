// configs/gaits/walk.yaml on the demo quadruped's joints and limits
// (configs/robots/quadruped.yaml): every sample of a stride must be inside
// the limits, and its speed and acceleration well below them.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {
namespace {

const std::string kWalk = std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/walk.yaml";

std::vector<JointSpec> quadruped() {
  std::vector<JointSpec> joints;
  for (const char* leg : {"lf", "rf", "lh", "rh"}) {
    for (const char* part : {"hip", "knee", "ankle"}) {
      JointSpec j;
      j.name = std::string(leg) + "_" + part;
      const double range = std::string(part) == "hip" ? 45.0 : 60.0;
      j.limits = {deg_to_rad(-range), deg_to_rad(range), deg_to_rad(300.0), deg_to_rad(3000.0)};
      joints.push_back(j);
    }
  }
  return joints;
}

int index_of(const std::vector<JointSpec>& joints, const std::string& name) {
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

TEST(WalkGait, TimingAndMapping) {
  const GaitFile gait = load_gait_file(kWalk);
  EXPECT_GE(gait.stride_frequency(), 0.8);
  EXPECT_LE(gait.stride_frequency(), 1.2);
  EXPECT_EQ(gait.find_limb("lh")->phase, 0.0);
  EXPECT_EQ(gait.find_limb("lf")->phase, 0.25);
  EXPECT_EQ(gait.find_limb("rh")->phase, 0.5);
  EXPECT_EQ(gait.find_limb("rf")->phase, 0.75);

  const auto joints = quadruped();
  const auto source = load_gait_source(kWalk, joints);
  EXPECT_EQ(source->driven_joints().size(), 12u);
}

TEST(WalkGait, StaysWithinTheQuadrupedsLimits) {
  const GaitFile gait = load_gait_file(kWalk);
  const auto joints = quadruped();
  const auto source = load_gait_source(kWalk, joints);
  const double period = 1.0 / gait.stride_frequency();
  const int steps = 20000;
  const double dt = period / steps;

  std::vector<double> prev(joints.size()), cur(joints.size()), next(joints.size());
  std::vector<double> peak_vel(joints.size(), 0.0), peak_acc(joints.size(), 0.0);
  source->sample(-dt, prev);
  source->sample(0.0, cur);
  for (int i = 0; i <= steps; ++i) {
    source->sample((i + 1) * dt, next);
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const JointLimits& lim = joints[j].limits;
      ASSERT_TRUE(std::isfinite(cur[j]));
      ASSERT_GE(cur[j], lim.min_position) << joints[j].name << " at t = " << i * dt;
      ASSERT_LE(cur[j], lim.max_position) << joints[j].name << " at t = " << i * dt;
      peak_vel[j] = std::max(peak_vel[j], std::abs(next[j] - cur[j]) / dt);
      peak_acc[j] = std::max(peak_acc[j], std::abs(next[j] - 2 * cur[j] + prev[j]) / (dt * dt));
    }
    prev = cur;
    cur = next;
  }
  for (std::size_t j = 0; j < joints.size(); ++j) {
    EXPECT_LT(peak_vel[j], joints[j].limits.max_velocity) << joints[j].name;
    EXPECT_LT(peak_acc[j], joints[j].limits.max_acceleration) << joints[j].name;
    EXPECT_GT(peak_vel[j], 0.0) << joints[j].name;  // every joint moves
  }
}

TEST(WalkGait, LateralSequenceAndPeriod) {
  const GaitFile gait = load_gait_file(kWalk);
  const auto joints = quadruped();
  const auto source = load_gait_source(kWalk, joints);
  const double period = 1.0 / gait.stride_frequency();
  std::vector<double> a(joints.size()), b(joints.size());
  for (double t : {0.0, 0.13, 0.5, 0.91}) {
    source->sample(t, a);
    // lf repeats lh a quarter stride later, rh half, rf three quarters.
    for (const auto& [leg, delay] : {std::pair{"lf", 0.25}, {"rh", 0.5}, {"rf", 0.75}}) {
      source->sample(t + delay * period, b);
      for (const char* part : {"_hip", "_knee", "_ankle"}) {
        const int lh = index_of(joints, std::string("lh") + part);
        const int other = index_of(joints, std::string(leg) + part);
        EXPECT_NEAR(b[static_cast<std::size_t>(other)], a[static_cast<std::size_t>(lh)], 1e-9)
            << leg << part << " at t = " << t;
      }
    }
    source->sample(t + period, b);
    for (std::size_t j = 0; j < joints.size(); ++j) EXPECT_NEAR(b[j], a[j], 1e-9);
  }
}

}  // namespace
}  // namespace animrt
