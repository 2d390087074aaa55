// Device health on the simulated Feetech STS arm, in lockstep: with
// `health: on` the cycle's Sync Read covers Present Position to Present
// Current, so every servo's supply, temperature, current and status bits
// arrive with its position; an injected overheat ends the run naming the
// servo and its temperature.

#include <gtest/gtest.h>

#include <string>

#include "animrt/bridge/feetech/feetech_bus.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace feetech_health_test {

const std::string kArm = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/arm_sts.yaml";

test::RigSettings health_on(const HealthLimits& limits, std::vector<SimHealthInjection> inject) {
  test::RigSettings settings;
  settings.edit = [limits, inject](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.health = limits;
    ft::BusOptions o;
    o.health = true;
    c.buses[0].options = o;
    c.buses[0].sim.health.inject = inject;
  };
  return settings;
}

TEST(FeetechHealth, EveryCycleCarriesSupplyTemperatureAndCurrent) {
  test::SimRig rig(kArm, health_on(HealthLimits{}, {}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  for (const auto& d : s.devices) {
    EXPECT_GE(d.health.readings + 2, s.cycles) << d.joint;
    // The board's rest values (the manual's 30 C, 12.1 V), sagging with the load.
    EXPECT_NEAR(d.health.min_temperature_c, 30.0, 0.5) << d.joint;
    EXPECT_NEAR(d.health.min_voltage_v, 12.0, 0.15) << d.joint;
    // 6.5 mA units: the idle 50 mA and more while moving.
    EXPECT_GT(d.health.peak_current_a, 0.04) << d.joint;
    EXPECT_LT(d.health.peak_current_a, 1.0) << d.joint;
    EXPECT_TRUE(d.status.reading.has_error_bits) << d.joint;
    EXPECT_EQ(d.status.reading.error_bits, 0u) << d.joint;
  }
}

TEST(FeetechHealth, AnInjectedOverheatEndsTheRunNamingTheServoAndTemperature) {
  HealthLimits limits;
  limits.temperature_fault_c = 60;
  // Below the servo's own Max Temperature (70): the runtime acts first.
  SimHealthInjection heat{3, 0.5, SimHealthInjection::Kind::temperature, 65.0};
  test::SimRig rig(kArm, health_on(limits, {heat}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 3"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("temperature 65 C (fault limit 60 C)"), std::string::npos)
      << s.faults[0];
}

TEST(FeetechHealth, ABlockedServoIsAStall) {
  HealthLimits limits;
  limits.stall_current_a = 1.0;
  limits.stall_time_s = 0.1;
  limits.stall_error_rad = 0.01;
  SimHealthInjection block{2, 0.5, SimHealthInjection::Kind::blocked, 1.0};
  test::SimRig rig(kArm, health_on(limits, {block}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 2"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("stall: current 1.40 A"), std::string::npos) << s.faults[0];
}

}  // namespace feetech_health_test
}  // namespace animrt
