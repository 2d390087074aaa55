// The physics' torso as it was at an earlier time: what a simulated IMU
// reports, so that lockstep runs read the same frames every time.

#include <gtest/gtest.h>

#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

TEST(MujocoJointPhysics, ReportsTheTorsoAsItWasAtAnEarlierTime) {
  const LoadedRobot robot = load_robot(kSourceRoot + "/configs/robots/horse.yaml");
  sim::MujocoJointPhysics physics(kSourceRoot + "/configs/models/horse.xml", robot.config.joints,
                                  robot.config.file, 0);
  // The right legs limp: the trunk rolls, so its attitude keeps changing.
  for (int j = 0; j < static_cast<int>(robot.config.joints.size()); ++j) {
    const JointSpec& joint = robot.config.joints[static_cast<std::size_t>(j)];
    physics.command(j, joint.home, joint.name[0] != 'r');
  }
  physics.keep_torso_history();
  physics.advance(100'000'000);
  const sim::TorsoMotion then = physics.torso_motion();
  physics.advance(200'000'000);
  const sim::TorsoMotion now = physics.torso_motion();
  ASSERT_NE(now.quat, then.quat);
  const sim::TorsoMotion asked = physics.torso_motion_at(0.1);
  EXPECT_EQ(asked.quat, then.quat);
  EXPECT_EQ(asked.rate_rad_s, then.rate_rad_s);
  EXPECT_EQ(asked.time_s, then.time_s);
  EXPECT_EQ(physics.torso_motion_at(0.2).quat, now.quat);
}

}  // namespace
}  // namespace animrt
