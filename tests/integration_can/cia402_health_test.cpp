// Device health of the CiA 402 drive on the CAN quadruped, in lockstep:
// with `health: on` a second TPDO carries the current actual value (per
// mille of the rated current read at configure) and the DC link voltage
// every SYNC; an undervoltage or a blocked joint faults the drive. A
// drive's config may name the manufacturer object of its temperature, which
// then travels in the same TPDO and meets the temperature limits.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace cia402_health_test {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr std::size_t kDrive = 2;

// The drive with health on, these limits and injected faults; `more` edits
// the drive's bus further.
test::RigSettings health_on(const HealthLimits& limits, std::vector<SimHealthInjection> inject,
                            std::function<void(BusConfig&)> more = nullptr) {
  test::RigSettings settings;
  settings.edit = [limits, inject, more](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    Cia402BusOptions o = options_of<Cia402BusOptions>(c.buses[kDrive].options);
    o.health = true;
    c.buses[kDrive].options = o;
    c.buses[kDrive].health_limits = limits;
    c.buses[kDrive].sim.health.inject = inject;
    if (more) more(c.buses[kDrive]);
  };
  return settings;
}

// A run that one fault of the rh_hip drive (node 32) ended, `what` in it.
void expect_drive_fault(const RunSummary& s, const std::string& what) {
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("32 (rh_hip)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find(what), std::string::npos) << s.faults[0];
}

// The devices of the drive's bus.
std::vector<DeviceReport> drive_devices(const test::SimRig& rig, const RunSummary& s) {
  std::vector<DeviceReport> out;
  for (const auto& d : s.devices) {
    if (d.bus == rig.config().buses[kDrive].name) out.push_back(d);
  }
  return out;
}

TEST(Cia402Health, ASecondTpdoCarriesCurrentAndSupply) {
  test::SimRig rig(kRobot, health_on(HealthLimits{}, {}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  const std::vector<DeviceReport> drives = drive_devices(rig, s);
  for (const auto& d : drives) {
    EXPECT_GT(d.health.readings, 50u) << d.joint;
    // The drive's 12 V supply sagging with its current; per mille of 2 A.
    EXPECT_NEAR(d.health.min_voltage_v, 12.0, 0.1) << d.joint;
    EXPECT_GT(d.health.peak_current_a, 0.04) << d.joint;
    EXPECT_LT(d.health.peak_current_a, 1.0) << d.joint;
    EXPECT_TRUE(std::isnan(d.health.max_temperature_c)) << d.joint;  // not in the profile
  }
  EXPECT_EQ(drives.size(), 1u);
}

TEST(Cia402Health, AnUndervoltageFaultsTheDrive) {
  HealthLimits limits;
  limits.voltage_warn_v = 11;
  limits.voltage_fault_v = 10;
  SimHealthInjection sag{32, 0.5, SimHealthInjection::Kind::supply, 9.0};
  test::SimRig rig(kRobot, health_on(limits, {sag}));
  expect_drive_fault(rig.run(3.0), "undervoltage: supply 9.0 V (fault limit 10 V)");
}

TEST(Cia402Health, ABlockedDriveIsAStall) {
  HealthLimits limits;
  limits.stall_current_a = 1.0;
  limits.stall_time_s = 0.1;
  limits.stall_error_rad = 0.01;
  SimHealthInjection block{32, 0.5, SimHealthInjection::Kind::blocked, 1.0};
  test::SimRig rig(kRobot, health_on(limits, {block}));
  expect_drive_fault(rig.run(3.0), "stall: current 1.40 A");
}

// CiA 402 has no temperature object; a drive's config names its
// manufacturer object, mapped into the health TPDO at configure.
void name_temperature(BusConfig& drive, const Cia402Temperature& temperature) {
  Cia402JointOptions o;
  o.has_temperature = true;
  o.temperature = temperature;
  drive.actuators[0].options = o;
}

test::RigSettings with_temperature(const HealthLimits& limits,
                                   std::vector<SimHealthInjection> inject) {
  return health_on(limits, std::move(inject), [](BusConfig& drive) {
    name_temperature(drive, Cia402Temperature{0x2022, 0x01, 16, true, 0.1});
  });
}

TEST(Cia402Health, ANamedTemperatureObjectTravelsInTheHealthTpdo) {
  test::SimRig rig(kRobot, with_temperature(HealthLimits{}, {}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  for (const auto& d : drive_devices(rig, s)) {
    EXPECT_GT(d.health.readings, 50u) << d.joint;
    // The simulated drive at rest: ambient 36 C, in 0.1 C counts.
    EXPECT_NEAR(d.health.min_temperature_c, 36.0, 0.15) << d.joint;
    EXPECT_NEAR(d.health.max_temperature_c, 36.0, 0.3) << d.joint;
    EXPECT_NEAR(d.health.min_voltage_v, 12.0, 0.1) << d.joint;  // still beside it
  }
}

TEST(Cia402Health, AnOverheatFaultsTheDriveNamingItsTemperature) {
  HealthLimits limits;
  limits.temperature_warn_c = 60;
  limits.temperature_fault_c = 70;
  SimHealthInjection heat{32, 0.5, SimHealthInjection::Kind::temperature, 75.0};
  test::SimRig rig(kRobot, with_temperature(limits, {heat}));
  expect_drive_fault(rig.run(3.0), "temperature 75 C (fault limit 70 C)");
}

TEST(Cia402Health, AnEightBitTemperatureInWholeDegrees) {
  test::SimRig rig(kRobot, health_on(HealthLimits{}, {}, [](BusConfig& drive) {
                     name_temperature(drive, Cia402Temperature{0x3000, 0x00, 8, false, 1.0});
                     drive.sim.health.ambient_c = 41.4;
                   }));
  const RunSummary s = rig.run(0.5);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  for (const auto& d : drive_devices(rig, s)) EXPECT_EQ(d.health.max_temperature_c, 41.0);
}

// The robot file's key: its place in the TPDO, and one located error.
std::string robot_with(const std::string& temperature) {
  std::ifstream in(kRobot);
  std::stringstream text;
  text << in.rdbuf();
  std::string robot = text.str();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = robot.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) robot.replace(at, from.size(), to);
  };
  replace("    heartbeat_ms: 20 ", "    health: true\n    heartbeat_ms: 20 ");
  replace("node_id: 32, ", "node_id: 32, temperature: " + temperature + ", ");
  replace("file: ../gaits/walk.yaml",
          "file: " + std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/walk.yaml");
  const std::string path = ::testing::TempDir() + "/cia402_temperature.yaml";
  std::ofstream(path) << robot;
  return path;
}

TEST(Cia402Health, TheTemperatureKeyNamesAManufacturerObject) {
  const RobotConfig c =
      load_robot_config(robot_with("{object: \"0x2022:0x01\", type: int16, scale: 0.1}"));
  const auto o = options_of<Cia402JointOptions>(c.buses[kDrive].actuators[0].options);
  ASSERT_TRUE(o.has_temperature);
  EXPECT_EQ(o.temperature.index, 0x2022);
  EXPECT_EQ(o.temperature.subindex, 1);
  EXPECT_EQ(o.temperature.bits, 16);
  EXPECT_DOUBLE_EQ(o.temperature.decode(0xFFF6), -1.0);  // -10 counts of 0.1 C
  try {
    load_robot_config(robot_with("{object: \"0x6041:0\", type: int16}"));
    ADD_FAILURE() << "a standard object was taken for a temperature";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "cia402_temperature.yaml:103:67: joints.rh_hip.actuator.temperature.object: "
                  "expected a manufacturer object"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace cia402_health_test
}  // namespace animrt
