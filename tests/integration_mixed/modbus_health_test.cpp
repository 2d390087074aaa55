// Device health of a Modbus drive on the simulated animatronic, in
// lockstep: the linear actuator's register map names its current,
// temperature, supply and fault code registers; with the bus's `health`
// key they are read with the position (packed) or apart (round_robin), and
// an overheat, a fault code or an undervoltage faults the drive while the
// other buses ramp home.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/runtime/mcap_reader.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace modbus_health_test {

const std::string kAnimatronic =
    std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";
constexpr std::size_t kTorso = 2;

test::RigSettings health(ModbusBusOptions::Health how, const HealthLimits& limits,
                         std::vector<SimHealthInjection> inject) {
  test::RigSettings settings;
  settings.edit = [how, limits, inject](RobotConfig& c) {
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
    BusConfig& torso = c.buses[kTorso];
    auto o = std::any_cast<ModbusBusOptions>(torso.options);
    o.health = how;
    torso.options = o;
    torso.health_limits = limits;
    torso.sim.health.inject = inject;
  };
  return settings;
}

const DeviceReport* torso(const RunSummary& s) {
  for (const auto& d : s.devices) {
    if (d.joint == "torso_lean") return &d;
  }
  return nullptr;
}

TEST(ModbusHealth, PackedEveryCycleCarriesCurrentTemperatureSupplyAndFaultCode) {
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::packed, HealthLimits{}, {}));
  const std::uint64_t before = dynamic_cast<ModbusBus&>(rig.bus(kTorso)).requests();
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  const auto* d = torso(s);
  ASSERT_NE(d, nullptr);
  EXPECT_GE(d->health.readings + 2, s.cycles);
  // The simulated drive's rest values: ambient 36 C, 12 V sagging with the load.
  EXPECT_NEAR(d->health.min_temperature_c, 36.0, 0.2);
  EXPECT_NEAR(d->health.min_voltage_v, 12.0, 0.1);
  EXPECT_GT(d->health.peak_current_a, 0.04);
  EXPECT_TRUE(d->status.reading.has_error_bits);
  EXPECT_EQ(d->status.reading.error_bits, 0u);
  // Still one read and one write request per cycle (and the lifecycle's).
  const std::uint64_t requests = dynamic_cast<ModbusBus&>(rig.bus(kTorso)).requests() - before;
  EXPECT_LE(requests, 2 * s.cycles + 12);
}

TEST(ModbusHealth, RoundRobinReadsHealthInARequestOfItsOwn) {
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::round_robin, HealthLimits{}, {}));
  const std::uint64_t before = dynamic_cast<ModbusBus&>(rig.bus(kTorso)).requests();
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  const auto* d = torso(s);
  ASSERT_NE(d, nullptr);
  // One slave: its health every cycle, in a third request per cycle.
  EXPECT_GE(d->health.readings + 2, s.cycles);
  EXPECT_NEAR(d->health.min_temperature_c, 36.0, 0.2);
  const std::uint64_t requests = dynamic_cast<ModbusBus&>(rig.bus(kTorso)).requests() - before;
  EXPECT_GE(requests, 3 * s.cycles - 3);
}

TEST(ModbusHealth, AnOverheatFaultsTheDriveNamingItsTemperature) {
  HealthLimits limits;
  limits.temperature_warn_c = 60;
  limits.temperature_fault_c = 70;
  SimHealthInjection heat{1, 0.5, SimHealthInjection::Kind::temperature, 85.0};
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::packed, limits, {heat}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 1 (torso_lean)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("temperature 85 C (fault limit 70 C)"), std::string::npos)
      << s.faults[0];
  // The others ramped home and stopped cleanly: only the drive faulted.
  for (const auto& d : s.devices) {
    if (d.joint != "torso_lean") {
      EXPECT_FALSE(d.status.faulted) << d.joint;
    }
  }
}

TEST(ModbusHealth, AFaultCodeFaultsTheDrive) {
  SimHealthInjection code{1, 0.5, SimHealthInjection::Kind::hardware_error, 0x21};
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::packed, HealthLimits{}, {code}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 1 (torso_lean)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("device error bits 0x21"), std::string::npos) << s.faults[0];
}

TEST(ModbusHealth, AnUndervoltageFaultsTheDrive) {
  HealthLimits limits;
  limits.voltage_warn_v = 11;
  limits.voltage_fault_v = 10;
  SimHealthInjection sag{1, 0.5, SimHealthInjection::Kind::supply, 9.0};
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::round_robin, limits, {sag}));
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("id 1 (torso_lean)"), std::string::npos) << s.faults[0];
  EXPECT_NE(s.faults[0].find("undervoltage: supply 9.0 V (fault limit 10 V)"), std::string::npos)
      << s.faults[0];
}

TEST(ModbusHealth, TheDrivesOwnLimitOverridesItsBuss) {
  HealthLimits bus;
  bus.temperature_fault_c = 70;
  SimHealthInjection heat{1, 0.5, SimHealthInjection::Kind::temperature, 60.0};
  test::RigSettings settings = health(ModbusBusOptions::Health::packed, bus, {heat});
  settings.edit = [edit = settings.edit](RobotConfig& c) {
    edit(c);
    HealthLimits own = *c.buses[kTorso].health_limits;
    own.temperature_fault_c = 50;
    c.buses[kTorso].actuators[0].health_limits = own;
  };
  test::SimRig rig(kAnimatronic, settings);
  const RunSummary s = rig.run(3.0);
  EXPECT_EQ(s.exit_code(), 4);
  ASSERT_EQ(s.faults.size(), 1u);
  EXPECT_NE(s.faults[0].find("temperature 60 C (fault limit 50 C)"), std::string::npos)
      << s.faults[0];
}

TEST(ModbusHealth, AWarningDoesNotStopTheRun) {
  HealthLimits limits;
  limits.temperature_warn_c = 60;
  limits.temperature_fault_c = 90;
  SimHealthInjection heat{1, 0.3, SimHealthInjection::Kind::temperature, 65.0};
  test::SimRig rig(kAnimatronic, health(ModbusBusOptions::Health::packed, limits, {heat}));
  const RunSummary s = rig.run(1.0);
  EXPECT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  const auto* d = torso(s);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->health.warnings, 1u);
  EXPECT_GT(d->health.max_temperature_c, 60.0);
}

// The number after "key": in a JSON text (NaN when absent).
double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? std::nan("")
                                 : std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

// The drive's health and a trunk IMU (pushed into a roll) in the MCAP
// recording and in the telemetry CSV.
TEST(ModbusHealth, HealthAndTheImuAreRecorded) {
  test::RigSettings settings = health(ModbusBusOptions::Health::packed, HealthLimits{}, {});
  settings.edit = [edit = settings.edit](RobotConfig& c) {
    edit(c);
    ImuConfig imu;
    imu.name = "trunk";
    imu.protocol = "bno08x_rvc";
    imu.stale_timeout_s = 0.5;
    imu.sim_push = ImuConfig::Push{true, false, 0.2, 1.0, 0.3};  // roll to 0.3 rad
    c.imus.push_back(imu);
  };
  test::SimRig rig(kAnimatronic, settings);
  const std::string csv = ::testing::TempDir() + "/modbus_health_imu.csv";
  RunOptions options = rig.options(1.5, csv);
  options.record_path = ::testing::TempDir() + "/modbus_health_imu.mcap";
  const RunSummary s = rig.run(options);
  ASSERT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);

  const mcap::ReadFile file = mcap::read_file(options.record_path);
  const mcap::ReadChannel* health_ch = file.channel("/devices/torso/torso_lean/health");
  const mcap::ReadChannel* imu_ch = file.channel("/imu");
  ASSERT_NE(health_ch, nullptr);
  ASSERT_NE(imu_ch, nullptr);
  EXPECT_EQ(health_ch->schema_name, "animrt.DeviceHealth");
  std::size_t health_messages = 0, imu_messages = 0;
  double last_temperature = 0.0, last_qx = 0.0;
  for (const mcap::ReadMessage& m : file.messages) {
    if (m.channel == health_ch->id) {
      ++health_messages;
      last_temperature = json_number(m.data, "temperature_c");
    } else if (m.channel == imu_ch->id) {
      ++imu_messages;
      last_qx = json_number(m.data, "qx");
    }
  }
  EXPECT_GE(health_messages + 2, s.cycles);
  EXPECT_GE(imu_messages + 5, s.cycles);
  EXPECT_NEAR(last_temperature, 36.0, 0.5);
  EXPECT_NEAR(last_qx, std::sin(0.15), 0.01);  // rolled 0.3 rad

  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line)) last = line;
  EXPECT_NE(header.find(",torso_lean_temp_c,"), std::string::npos) << header;
  const auto at = header.find(",trunk_qw,trunk_qx,trunk_qy,trunk_qz,trunk_rate_x_rad_s");
  ASSERT_NE(at, std::string::npos) << header;
  // The last row's trunk_qx: the field after as many commas as precede it.
  const auto column = static_cast<std::size_t>(
      std::count(header.begin(), header.begin() + static_cast<long>(at) + 1, ',') + 1);
  std::size_t field = 0, pos = 0;
  while (field < column && pos != std::string::npos) {
    pos = last.find(',', pos) + 1;
    ++field;
  }
  EXPECT_NEAR(std::strtod(last.c_str() + pos, nullptr), std::sin(0.15), 0.01) << last;
}

// An IMU that falls silent mid-run: each /imu message carries the cycle's
// late cycles and missing reports so far, so the recording shows when the
// part faltered, up to the summary's counts at the end.
TEST(ModbusHealth, ALateImuIsCountedInTheRecording) {
  test::RigSettings settings = health(ModbusBusOptions::Health::packed, HealthLimits{}, {});
  settings.edit = [edit = settings.edit](RobotConfig& c) {
    edit(c);
    ImuConfig imu;
    imu.name = "trunk";
    imu.protocol = "bno08x_rvc";
    imu.stale_timeout_s = 5.0;  // late, not stale: the run goes on
    imu.sim_silent_at_s = 0.6;
    c.imus.push_back(imu);
  };
  test::SimRig rig(kAnimatronic, settings);
  RunOptions options = rig.options(1.2, "");
  options.record_path = ::testing::TempDir() + "/modbus_health_late_imu.mcap";
  const RunSummary s = rig.run(options);
  ASSERT_EQ(s.exit_code(), 0) << (s.faults.empty() ? "" : s.faults[0]);
  ASSERT_EQ(s.imus.size(), 1u);

  const mcap::ReadFile file = mcap::read_file(options.record_path);
  const mcap::ReadChannel* imu_ch = file.channel("/imu");
  ASSERT_NE(imu_ch, nullptr);
  double first_late = -1.0, last_late = -1.0, last_missing = -1.0;
  for (const mcap::ReadMessage& m : file.messages) {
    if (m.channel != imu_ch->id) continue;
    if (first_late < 0.0) first_late = json_number(m.data, "late_cycles");
    last_late = json_number(m.data, "late_cycles");
    last_missing = json_number(m.data, "missing_reports");
  }
  EXPECT_LE(first_late, 1.0);     // the part was on time at first
  EXPECT_GE(last_late, 40.0);     // 0.6 s silent at 100 Hz: ~55 late cycles
  EXPECT_GE(last_missing, 40.0);  // and ~55 reports not sent
  EXPECT_LE(last_late, static_cast<double>(s.imus[0].late_cycles));
  EXPECT_LE(last_missing, static_cast<double>(s.imus[0].missing_reports));
}

}  // namespace modbus_health_test
}  // namespace animrt
