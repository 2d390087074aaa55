// Device health of the CiA 402 drive on the CAN quadruped, in lockstep:
// with `health: on` a second TPDO carries the current actual value (per
// mille of the rated current read at configure) and the DC link voltage
// every SYNC; an undervoltage or a blocked joint faults the drive.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "animrt/bridge/can/can_options.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace cia402_health_test {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr std::size_t kDrive = 2;

test::RigSettings health_on(const HealthLimits& limits, std::vector<SimHealthInjection> inject) {
  test::RigSettings settings;
  settings.edit = [limits, inject](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    Cia402BusOptions o = options_of<Cia402BusOptions>(c.buses[kDrive].options);
    o.health = true;
    c.buses[kDrive].options = o;
    c.buses[kDrive].health_limits = limits;
    c.buses[kDrive].sim.health.inject = inject;
  };
  return settings;
}

TEST(Cia402Health, ASecondTpdoCarriesCurrentAndSupply) {
  test::SimRig rig(kRobot, health_on(HealthLimits{}, {}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  int drives = 0;
  for (const auto& d : s.devices) {
    if (d.bus != rig.config().buses[kDrive].name) continue;
    ++drives;
    EXPECT_GT(d.health.readings, 50u) << d.joint;
    // The drive's 12 V supply sagging with its current; per mille of 2 A.
    EXPECT_NEAR(d.health.min_voltage_v, 12.0, 0.1) << d.joint;
    EXPECT_GT(d.health.peak_current_a, 0.04) << d.joint;
    EXPECT_LT(d.health.peak_current_a, 1.0) << d.joint;
    EXPECT_TRUE(std::isnan(d.health.max_temperature_c)) << d.joint;  // not in the profile
  }
  EXPECT_EQ(drives, 1);
}

TEST(Cia402Health, AnUndervoltageFaultsTheDrive) {
  HealthLimits limits;
  limits.voltage_warn_v = 11;
  limits.voltage_fault_v = 10;
  SimHealthInjection sag{32, 0.5, SimHealthInjection::Kind::supply, 9.0};
  test::SimRig rig(kRobot, health_on(limits, {sag}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("32 (rh_hip)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("undervoltage: supply 9.0 V (fault limit 10 V)"), std::string::npos)
      << s.faults[0];
}

TEST(Cia402Health, ABlockedDriveIsAStall) {
  HealthLimits limits;
  limits.stall_current_a = 1.0;
  limits.stall_time_s = 0.1;
  limits.stall_error_rad = 0.01;
  SimHealthInjection block{32, 0.5, SimHealthInjection::Kind::blocked, 1.0};
  test::SimRig rig(kRobot, health_on(limits, {block}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("32 (rh_hip)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("stall: current 1.40 A"), std::string::npos) << s.faults[0];
}

}  // namespace cia402_health_test
}  // namespace animrt
