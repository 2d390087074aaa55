// The simulated BNO08x on the physics' torso, in lockstep: the horse goes
// limp and falls, and every frame the host decodes carries MuJoCo's torso
// quaternion at that step, to the part's 0.01 degree.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include "animrt/bridge/imu/rvc_reader.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/imu/rvc_sim_imu.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"
#include "support/files.hpp"

namespace animrt::imu_physics_test {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The angle between two attitudes (rad).
double angle_between(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  const double dot = std::abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
  return 2.0 * std::acos(std::min(1.0, dot));
}

TEST(ImuOnPhysics, ReportsTheTorsosAttitudeInLockstep) {
  const LoadedRobot robot = load_robot(kSourceRoot + "/configs/robots/horse.yaml");
  ManualClock clock(0);
  sim::MujocoJointPhysics physics(kSourceRoot + "/configs/models/horse.xml", robot.config.joints,
                                  robot.config.file, 0);
  // The right legs limp, the others held: the horse falls onto its right side.
  for (int j = 0; j < static_cast<int>(robot.config.joints.size()); ++j) {
    const JointSpec& joint = robot.config.joints[static_cast<std::size_t>(j)];
    physics.command(j, joint.home, joint.name[0] != 'r');
  }
  ImuConfig config;
  config.name = "trunk";
  config.protocol = "bno08x_rvc";
  config.mount_ypr_rad = {0.0, 0.0, 180 * kDeg};  // mounted upside down
  sim::RvcSimImu part(config, clock, 0, [&physics](double) {
    const sim::TorsoMotion torso = physics.torso_motion();
    return sim::TrunkState{torso.quat, torso.accel_m_s2};
  });
  imu::RvcReader reader(open_serial(part.port(), 115200), config, clock, 0);

  // The frame sent at t = 0 gone by, or taken.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ImuReading reading;
  (void)reader.readings().take(reading);

  double worst = 0.0, largest_tilt = 0.0;
  int compared = 0;
  for (int k = 1; k <= 150; ++k) {  // 1.5 s, a frame every 10 ms
    const Nanos t = k * 10'000'000LL;
    const std::uint64_t before = reader.frames();
    physics.advance(t);  // the physics is at t and stays there ...
    clock.set(t);        // ... while the part sends its frame for t
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (reader.frames() == before && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    const bool got = reader.readings().take(reading);
    ASSERT_TRUE(got) << "no frame for t=" << to_seconds(t);
    const sim::TorsoMotion torso = physics.torso_motion();
    worst = std::max(worst, angle_between(reading.quat, torso.quat));
    largest_tilt = std::max(largest_tilt, tilt_of(torso.quat));
    ++compared;
  }
  EXPECT_EQ(compared, 150);
  EXPECT_GT(largest_tilt, 10 * kDeg);  // it did fall over: the attitude changed a lot
  EXPECT_LT(worst, 0.02 * kDeg);       // three angles rounded to 0.01 degree
  EXPECT_EQ(reader.checksum_errors(), 0u);
  EXPECT_EQ(reader.lost_frames(), 0u);
}

}  // namespace
}  // namespace animrt::imu_physics_test
