// Device health from the MIT motors' replies, in lockstep on the CAN
// quadruped: every reply's torque and (8-byte replies) temperature reach the
// summary and telemetry; the CiA 402 drive's bus reads none (n/a).

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "support/sim_rig.hpp"

namespace animrt {
namespace mit_health_test {

TEST(MitHealth, RepliesCarryTorqueAndTemperature) {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
  };
  test::SimRig rig(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml", settings);
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  int mit = 0;
  for (std::size_t i = 0; i < s.devices.size(); ++i) {
    const auto& d = s.devices[i];
    if (d.bus == rig.config().buses[2].name) {  // the CiA 402 drive: not read
      EXPECT_EQ(d.health.readings, 0u) << d.joint;
      EXPECT_TRUE(std::isnan(d.health.max_temperature_c)) << d.joint;
      continue;
    }
    ++mit;
    EXPECT_GE(d.health.readings + 2, s.cycles) << d.joint;
    // The simulated motor's temperature (ambient 36 C, warming slowly with
    // the current its motion draws), and the torque its gains produce
    // while it follows the gait.
    EXPECT_DOUBLE_EQ(d.health.min_temperature_c, 36.0) << d.joint;
    EXPECT_LE(d.health.max_temperature_c, 37.0) << d.joint;
    EXPECT_GT(d.health.peak_torque_nm, 0.0) << d.joint;
    EXPECT_TRUE(std::isnan(d.health.peak_current_a)) << d.joint;
  }
  EXPECT_GT(mit, 0);
  EXPECT_NE(format_summary(s).find("peak torque"), std::string::npos);
}

TEST(MitHealth, AnInjectedOverheatEndsTheRunNamingTheMotorAndTemperature) {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.health.temperature_warn_c = 60;
    c.safety.health.temperature_fault_c = 70;
    c.buses[0].sim.health.inject = {
        SimHealthInjection{2, 0.5, SimHealthInjection::Kind::temperature, 85.0}};
  };
  test::SimRig rig(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml", settings);
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 2 ("), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("temperature 85 C (fault limit 70 C)"), std::string::npos)
      << s.faults[0];
}

}  // namespace mit_health_test
}  // namespace animrt
