// Device health end to end on the simulated Dynamixel servos, in lockstep:
// the health registers read with the positions (packed into the Indirect
// Data region) or one servo per cycle (round robin), the limits of the
// safety section (a fault ends the run with exit 4 naming the device and the
// value, a warning is counted and the run goes on), and the simulated
// servos' thermal, supply and stall model behind them.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/bridge/dynamixel/x_models.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace health_test {

const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";

// The quadruped with health read `how`, short ramps, and `limits`.
test::RigSettings health_settings(dxl::HealthRead how, const HealthLimits& limits,
                                  std::vector<SimHealthInjection> inject = {}) {
  test::RigSettings settings;
  settings.edit = [how, limits, inject](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    c.safety.health = limits;
    for (auto& bus : c.buses) {
      dxl::BusOptions o = dxl::bus_options(bus);
      o.health = how;
      bus.options = o;
      bus.sim.health.inject = inject;
    }
  };
  return settings;
}

const DeviceReport& device(const RunSummary& s, const std::string& joint) {
  for (const auto& d : s.devices) {
    if (d.joint == joint) return d;
  }
  throw std::runtime_error("no device " + joint);
}

std::vector<std::string> csv_header(const std::string& path) {
  std::ifstream in(path);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> out;
  std::stringstream hs(line);
  while (std::getline(hs, cell, ',')) out.push_back(cell);
  return out;
}

TEST(DeviceHealth, PackedReadsReportTemperatureCurrentAndVoltageOfEveryServo) {
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, HealthLimits{}));
  const std::string csv = ::testing::TempDir() + "/health_packed.csv";
  const RunSummary s = rig.run(1.0, csv);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  ASSERT_EQ(s.devices.size(), 12u);
  for (const auto& d : s.devices) {
    // Every cycle carries the health of every servo.
    EXPECT_GE(d.health.readings + 2, s.cycles) << d.joint;
    // The simulated servo's defaults: 36 C at rest, 12 V supply with a
    // small sag, an idle current of 50 mA and more while moving.
    EXPECT_NEAR(d.health.min_temperature_c, 36.0, 0.5) << d.joint;
    EXPECT_NEAR(d.health.min_voltage_v, 11.9, 0.15) << d.joint;
    EXPECT_GT(d.health.peak_current_a, 0.06) << d.joint;
    EXPECT_LT(d.health.peak_current_a, 1.0) << d.joint;
    EXPECT_EQ(d.status.reading.error_bits, 0u) << d.joint;
    EXPECT_TRUE(d.status.reading.has_error_bits) << d.joint;
  }
  // The existing columns come first and unchanged; five per servo follow.
  const auto header = csv_header(csv);
  ASSERT_EQ(header.size(), 1u + 24u + 60u);
  EXPECT_EQ(header[0], "time_s");
  EXPECT_EQ(header[1], s.joints[0].name + "_cmd_rad");
  EXPECT_EQ(header[25], s.joints[0].name + "_temp_c");
  EXPECT_EQ(header[26], s.joints[0].name + "_current_a");
  EXPECT_EQ(header[27], s.joints[0].name + "_voltage_v");
  EXPECT_EQ(header[28], s.joints[0].name + "_torque_nm");
  EXPECT_EQ(header[29], s.joints[0].name + "_error_bits");
}

TEST(DeviceHealth, RoundRobinReadsOneServoPerCycle) {
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::round_robin, HealthLimits{}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  for (const auto& d : s.devices) {
    // A twelfth of the cycles each, give or take one turn.
    EXPECT_NEAR(static_cast<double>(d.health.readings), static_cast<double>(s.cycles) / 12.0, 2.0)
        << d.joint;
    EXPECT_NEAR(d.health.max_temperature_c, 36.0, 0.5) << d.joint;
    EXPECT_NEAR(d.health.min_voltage_v, 11.9, 0.15) << d.joint;
  }
}

TEST(DeviceHealth, WithoutHealthReadsTheSummarySaysNotRead) {
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::off, HealthLimits{}));
  const std::string csv = ::testing::TempDir() + "/health_off.csv";
  const RunSummary s = rig.run(0.3, csv);
  EXPECT_EQ(s.exit_code(), 0);
  for (const auto& d : s.devices) {
    EXPECT_EQ(d.health.readings, 0u);
    EXPECT_TRUE(std::isnan(d.health.max_temperature_c));
  }
  EXPECT_EQ(csv_header(csv).size(), 25u);
  EXPECT_EQ(format_summary(s).find("health:"), std::string::npos);
}

TEST(DeviceHealth, AnInjectedOverheatEndsTheRunNamingTheDeviceAndTemperature) {
  HealthLimits limits;
  limits.temperature_warn_c = 60;
  limits.temperature_fault_c = 70;
  // lh_ankle (id 9) heats to 75 C half a second in: above our fault limit,
  // below the servo's own Temperature Limit (80), so the runtime acts first.
  SimHealthInjection heat{9, 0.5, SimHealthInjection::Kind::temperature, 75.0};
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, limits, {heat}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 9 (lh_ankle)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("temperature 75 C (fault limit 70 C)"), std::string::npos)
      << s.faults[0];
  EXPECT_TRUE(device(s, "lh_ankle").status.faulted);
  EXPECT_NEAR(device(s, "lh_ankle").health.max_temperature_c, 75.0, 0.5);
  EXPECT_LT(s.motion_time_s, 1.0);
  // The others ramped home.
  for (const auto& bus : rig.config().buses) {
    for (const auto& a : bus.actuators) {
      if (a.joint == "lh_ankle") continue;
      EXPECT_NEAR(rig.sims[0]->device_position(a.device_id), 0.0, 0.02) << a.joint;
    }
  }
}

TEST(DeviceHealth, AnOverheatPastTheServosOwnLimitIsItsErrorBits) {
  HealthLimits limits;  // no temperature limit of ours: the servo's Overheating bit acts
  SimHealthInjection heat{9, 0.5, SimHealthInjection::Kind::temperature, 85.0};
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, limits, {heat}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 9 (lh_ankle)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("device error bits 0x04"), std::string::npos) << s.faults[0];
}

TEST(DeviceHealth, AWarningIsCountedAndTheRunGoesOn) {
  HealthLimits limits;
  limits.temperature_warn_c = 60;
  limits.temperature_fault_c = 90;
  SimHealthInjection heat{4, 0.5, SimHealthInjection::Kind::temperature, 65.0};
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, limits, {heat}));
  const RunSummary s = rig.run(1.5);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  EXPECT_NEAR(s.motion_time_s, 1.5, 0.01);
  const auto& d = s.devices[3];
  ASSERT_EQ(d.status.device_id, 4);
  // The servo cools only slowly: one episode, one warning.
  EXPECT_EQ(d.health.warnings, 1u);
  ASSERT_EQ(s.health_warnings.size(), 1u);
  EXPECT_NE(s.health_warnings[0].find("id 4"), std::string::npos) << s.health_warnings[0];
  EXPECT_NE(s.health_warnings[0].find("temperature 65 C (warning limit 60 C)"), std::string::npos)
      << s.health_warnings[0];
  EXPECT_NE(format_summary(s).find("WARNING bus legs id 4"), std::string::npos);
}

TEST(DeviceHealth, ABlockedJointIsAStall) {
  HealthLimits limits;
  limits.stall_current_a = 1.0;
  limits.stall_time_s = 0.1;
  // lf_knee (id 2, moving in the gait) blocked from 0.6 s: it draws the stall
  // current and stops following.
  SimHealthInjection block{2, 0.6, SimHealthInjection::Kind::blocked, 1.0};
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, limits, {block}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 2"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("stall: current 1.40 A"), std::string::npos) << s.faults[0];
  // Caught before the following-error watch (0.5 s window) would have been.
  EXPECT_EQ(s.faults[0].find("following error"), std::string::npos);
}

TEST(DeviceHealth, ASaggingSupplyIsUndervoltage) {
  HealthLimits limits;
  limits.voltage_warn_v = 11.0;
  limits.voltage_fault_v = 10.0;
  test::SimRig rig(kQuadruped, health_settings(dxl::HealthRead::packed, limits));
  bool done = false;
  rig.probe->on_sample = [&](double t) {
    // From the C++ side, mid-run: the supply of id 5 drops to 9.5 V.
    if (!done && t >= 0.4) {
      rig.sims[0]->inject_device_health(5, {5, 0, SimHealthInjection::Kind::supply, 9.5});
      done = true;
    }
  };
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 5"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("undervoltage: supply 9.5 V (fault limit 10 V)"), std::string::npos)
      << s.faults[0];
}

}  // namespace health_test
}  // namespace animrt
