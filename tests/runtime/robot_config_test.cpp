#include "animrt/runtime/robot_config.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

namespace fs = std::filesystem;

// Each test gets its own folder holding robots/robot.yaml and gaits/gait.yaml
// (the loader only checks that the gait file exists).
class RobotConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("animrt_robot_config_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    write_file(dir_ / "gaits" / "gait.yaml", "# a gait\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string robot_path() const { return (dir_ / "robots" / "robot.yaml").string(); }

  RobotConfig load(const std::string& text) {
    write_file(robot_path(), text);
    return load_robot_config(robot_path());
  }

  // The full message of the InputError that loading `text` raises.
  std::string error_of(const std::string& text) {
    try {
      (void)load(text);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }

  // Expected message: the robot file's path followed by `rest`.
  std::string at(const std::string& rest) const { return robot_path() + ":" + rest; }

  fs::path dir_;
};

// A small valid robot; the error tests below are variations of it.
const char* const kMinimal = R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1}
motion: {type: gait, file: ../gaits/gait.yaml}
)";

// ---------------------------------------------------------------- valid files

TEST_F(RobotConfigTest, ShippedQuadrupedHasTheDocumentedValues) {
  // A copy next to a stand-in gait, so the robot file itself is checked even
  // before configs/gaits/walk.yaml exists.
  const fs::path copy = dir_ / "robots" / "quadruped.yaml";
  write_file(copy, read_file(kSourceRoot + "/configs/robots/quadruped.yaml"));
  write_file(dir_ / "gaits" / "walk.yaml", "# stand-in\n");
  write_file(dir_ / "models" / "quadruped.xml", "<!-- stand-in -->\n");
  const RobotConfig c = load_robot_config(copy.string());

  EXPECT_EQ(c.file, copy.string());
  EXPECT_EQ(c.name, "quadruped");
  EXPECT_DOUBLE_EQ(c.rate_hz, 200.0);
  EXPECT_DOUBLE_EQ(c.safety.watchdog_timeout_s, 0.1);
  EXPECT_DOUBLE_EQ(c.safety.start_ramp_s, 2.0);
  EXPECT_DOUBLE_EQ(c.safety.stop_ramp_s, 2.0);

  const char* const names[] = {"lf_hip", "lf_knee", "lf_ankle", "rf_hip", "rf_knee", "rf_ankle",
                               "lh_hip", "lh_knee", "lh_ankle", "rh_hip", "rh_knee", "rh_ankle"};
  ASSERT_EQ(c.joints.size(), 12u);
  for (int i = 0; i < 12; ++i) {
    SCOPED_TRACE(names[i]);
    const JointSpec& j = c.joints[i];
    EXPECT_EQ(j.name, names[i]);
    const double limit_deg = (i % 3 == 0) ? 45.0 : 60.0;  // hips 45, knees and ankles 60
    EXPECT_DOUBLE_EQ(j.limits.min_position, -limit_deg * kPi / 180.0);
    EXPECT_DOUBLE_EQ(j.limits.max_position, limit_deg * kPi / 180.0);
    EXPECT_DOUBLE_EQ(j.limits.max_velocity, 300.0 * kPi / 180.0);
    EXPECT_DOUBLE_EQ(j.limits.max_acceleration, 3000.0 * kPi / 180.0);
    EXPECT_DOUBLE_EQ(j.home, 0.0);
  }
  EXPECT_NEAR(c.joints[1].limits.min_position, -1.0471975511965976, 1e-15);  // -60 deg

  ASSERT_EQ(c.buses.size(), 1u);
  const BusConfig& bus = c.buses[0];
  EXPECT_EQ(bus.name, "legs");
  EXPECT_EQ(bus.protocol, "dynamixel2");
  EXPECT_EQ(bus.port, "/dev/ttyUSB0");
  EXPECT_EQ(bus.baud, 1'000'000);
  EXPECT_DOUBLE_EQ(bus.timeout_s, 0.004);
  EXPECT_DOUBLE_EQ(bus.sim.time_constant_s, 0.03);
  EXPECT_NEAR(bus.sim.max_speed_rad_s, 5.759586531581287, 1e-12);  // 330 deg/s
  EXPECT_TRUE(bus.sim.wire_time);
  EXPECT_EQ(bus.sim.return_delay_us, 0);
  EXPECT_EQ(bus.where.file, copy.string());
  EXPECT_GT(bus.where.line, 0);

  ASSERT_EQ(bus.actuators.size(), 12u);
  for (int i = 0; i < 12; ++i) {
    SCOPED_TRACE(names[i]);
    const ActuatorBinding& a = bus.actuators[i];
    EXPECT_EQ(a.joint, names[i]);
    EXPECT_EQ(a.joint_index, i);
    EXPECT_EQ(a.device_id, i + 1);
    EXPECT_NEAR(a.ticks_per_rad, 651.8986469044033, 1e-9);  // 4096 / 2pi
    EXPECT_EQ(a.zero_ticks, 2048);
    const bool right = names[i][0] == 'r';
    EXPECT_EQ(a.direction, right ? -1 : 1);
  }
  // +45 deg on a hip: half a quarter turn from the centre, mirrored on the right.
  EXPECT_EQ(bus.actuators[0].to_ticks(c.joints[0].limits.max_position), 2560);
  EXPECT_EQ(bus.actuators[3].to_ticks(c.joints[3].limits.max_position), 1536);

  EXPECT_EQ(c.motion.type, "gait");
  EXPECT_EQ(c.motion.file, (dir_ / "robots" / ".." / "gaits" / "walk.yaml").string());
  EXPECT_TRUE(fs::exists(c.motion.file));
  EXPECT_EQ(c.motion.where.file, copy.string());
  EXPECT_GT(c.motion.where.line, 0);
}

TEST_F(RobotConfigTest, ShippedQuadrupedLoadsInPlace) {
  const std::string walk = kSourceRoot + "/configs/gaits/walk.yaml";
  ASSERT_TRUE(fs::exists(walk)) << walk << " is missing";
  const std::string path = kSourceRoot + "/configs/robots/quadruped.yaml";
  const RobotConfig c = load_robot_config(path);
  EXPECT_EQ(c.joints.size(), 12u);
  EXPECT_EQ(c.motion.file, kSourceRoot + "/configs/robots/../gaits/walk.yaml");
  EXPECT_TRUE(fs::equivalent(c.motion.file, walk));
  EXPECT_TRUE(fs::equivalent(c.model, kSourceRoot + "/configs/models/quadruped.xml"));
}

TEST_F(RobotConfigTest, TheFigureModelIsOptionalAndMustExist) {
  EXPECT_EQ(load(kMinimal).model, "");
  write_file(dir_ / "models" / "figure.xml", "<mujoco/>\n");
  const RobotConfig c = load(std::string(kMinimal) + "model: ../models/figure.xml\n");
  EXPECT_EQ(c.model, (dir_ / "robots" / ".." / "models" / "figure.xml").string());
  EXPECT_EQ(c.model_where.line, 10);
  EXPECT_EQ(error_of(std::string(kMinimal) + "model: ../models/missing.xml\n"),
            at("10:8: model: file not found: \"../models/missing.xml\" (resolved against the "
               "robot file's folder to \"" +
               (dir_ / "robots" / ".." / "models" / "missing.xml").string() + "\")"));
  EXPECT_EQ(error_of(std::string(kMinimal) + "model: ../models\n"),
            at("10:8: model: \"../models\" (resolved against the robot file's folder to \"" +
               (dir_ / "robots" / ".." / "models").string() + "\") is a directory"));
}

TEST_F(RobotConfigTest, OptionalKeysTakeTheirDefaults) {
  const RobotConfig c = load(kMinimal);
  EXPECT_DOUBLE_EQ(c.rate_hz, 100.0);
  EXPECT_DOUBLE_EQ(c.safety.watchdog_timeout_s, 0.1);
  EXPECT_DOUBLE_EQ(c.safety.start_ramp_s, 2.0);
  EXPECT_DOUBLE_EQ(c.safety.stop_ramp_s, 2.0);
  ASSERT_EQ(c.buses.size(), 1u);
  EXPECT_EQ(c.buses[0].baud, 1'000'000);
  EXPECT_DOUBLE_EQ(c.buses[0].timeout_s, 0.004);
  EXPECT_DOUBLE_EQ(c.buses[0].sim.time_constant_s, 0.02);
  EXPECT_DOUBLE_EQ(c.buses[0].sim.max_speed_rad_s, 6.0);
  EXPECT_FALSE(c.buses[0].sim.wire_time);
  EXPECT_EQ(c.buses[0].sim.return_delay_us, 0);
  ASSERT_EQ(c.buses[0].actuators.size(), 1u);
  const ActuatorBinding& a = c.buses[0].actuators[0];
  EXPECT_DOUBLE_EQ(a.ticks_per_rad, 4096.0 / (2.0 * kPi));
  EXPECT_EQ(a.zero_ticks, 2048);
  EXPECT_EQ(a.direction, 1);
  EXPECT_DOUBLE_EQ(c.joints[0].home, 0.0);
  EXPECT_EQ(c.buses[0].where.line, 4);
  EXPECT_EQ(c.buses[0].where.column, 3);
  EXPECT_EQ(c.motion.where.line, 9);
  EXPECT_EQ(c.motion.where.column, 28);
}

TEST_F(RobotConfigTest, ActuatorsFollowJointOrderAcrossBuses) {
  const RobotConfig c = load(R"(name: two buses
loop: {rate_hz: 500}
buses:
  left: {protocol: dynamixel2, port: /dev/ttyUSB0, baud: 4000000, timeout_ms: 2.5}
  right: {protocol: dynamixel2, port: /dev/ttyUSB1}
joints:
  a:
    limits: {min_deg: 0, max_deg: 90, velocity_dps: 90, acceleration_dps2: 900}
    home_deg: 30
    actuator: {bus: right, id: 7, ticks_per_rad: 1000, zero_ticks: 100, direction: 1}
  b:
    limits: {min_deg: -20, max_deg: 20, velocity_dps: 90, acceleration_dps2: 900}
    actuator: {bus: left, id: 7, direction: -1}
  c:
    limits: {min_deg: -20, max_deg: 20, velocity_dps: 90, acceleration_dps2: 900}
    actuator: {bus: right, id: 0, ticks_per_rev: 2048, zero_ticks: 1024}
motion: {type: gait, file: ../gaits/gait.yaml}
)");
  ASSERT_EQ(c.joints.size(), 3u);
  EXPECT_DOUBLE_EQ(c.joints[0].home, 30.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(c.buses[0].timeout_s, 0.0025);
  EXPECT_EQ(c.buses[0].baud, 4'000'000);
  ASSERT_EQ(c.buses[0].actuators.size(), 1u);
  EXPECT_EQ(c.buses[0].actuators[0].joint, "b");
  EXPECT_EQ(c.buses[0].actuators[0].joint_index, 1);
  EXPECT_EQ(c.buses[0].actuators[0].direction, -1);
  ASSERT_EQ(c.buses[1].actuators.size(), 2u);
  EXPECT_EQ(c.buses[1].actuators[0].joint, "a");
  EXPECT_EQ(c.buses[1].actuators[0].joint_index, 0);
  EXPECT_DOUBLE_EQ(c.buses[1].actuators[0].ticks_per_rad, 1000.0);
  EXPECT_EQ(c.buses[1].actuators[0].zero_ticks, 100);
  EXPECT_EQ(c.buses[1].actuators[0].to_ticks(c.joints[0].limits.max_position), 1671);
  EXPECT_EQ(c.buses[1].actuators[1].joint, "c");
  EXPECT_EQ(c.buses[1].actuators[1].joint_index, 2);
  EXPECT_EQ(c.buses[1].actuators[1].device_id, 0);
  EXPECT_DOUBLE_EQ(c.buses[1].actuators[1].ticks_per_rad, 2048.0 / (2.0 * kPi));
}

TEST_F(RobotConfigTest, AbsoluteMotionFileIsKeptAsGiven) {
  const std::string gait = (dir_ / "gaits" / "gait.yaml").string();
  std::string text = kMinimal;
  text.replace(text.find("../gaits/gait.yaml"), 18, gait);
  EXPECT_EQ(load(text).motion.file, gait);
}

// ------------------------------------------------------------ unknown keys

TEST_F(RobotConfigTest, UnknownKeysAreRejectedAtEveryLevel) {
  EXPECT_EQ(error_of(std::string(kMinimal) + "colour: red\n"),
            at("10:1: colour: unknown key (expected one of: name, loop, safety, buses, joints, "
               "motion, model, imus)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100, rate: 5}
)"),
            at("2:22: loop.rate: unknown key (expected one of: rate_hz)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
safety: {watchdog_s: 1}
)"),
            at("3:10: safety.watchdog_s: unknown key (expected one of: watchdog_timeout_s, "
               "start_ramp_s, stop_ramp_s, start_ramp_max_s, stop_deadline_s, "
               "following_error_deg, following_error_mm, following_error_window_s, health, "
               "tilt_limit_deg, tilt_time_s, on_tilt, tilt_hold_s)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b:
    protocol: dynamixel2
    port: /dev/ttyUSB0
    parity: none
)"),
            at("7:5: buses.b.parity: unknown key (expected one of: protocol, port, baud, "
               "timeout_ms, fast_read, model, device_watchdog_ms, health, sim, health_limits)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b:
    protocol: dynamixel2
    port: /dev/ttyUSB0
    sim: {max_speed_rad_s: 6}
)"),
            at("7:11: buses.b.sim.max_speed_rad_s: unknown key (expected one of: "
               "time_constant_s, max_speed_dps, wire_time, return_delay_us, "
               "firmware_version, health, inject, switches)"));
  EXPECT_EQ(
      error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    home: 0
)"),
      at("8:5: joints.j1.home: unknown key (expected one of: type, limits, home_deg, actuator)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
)"),
            at("7:14: joints.j1.limits.min: unknown key (expected one of: min_deg, max_deg, "
               "velocity_dps, acceleration_dps2)"));
  EXPECT_EQ(
      error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1, inverted: true}
)"),
      at("8:31: joints.j1.actuator.inverted: unknown key (expected one of: bus, id, "
         "ticks_per_rev, ticks_per_rad, zero_ticks, direction, model, multi_turn, health_limits)"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1}
motion: {type: gait, file: ../gaits/gait.yaml, speed: 2}
)"),
            at("9:48: motion.speed: unknown key (expected one of: type, file)"));
}

// ------------------------------------------------------------- wrong types

TEST_F(RobotConfigTest, WrongTypesNameWhatWasFound) {
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: fast}\n"),
            at("2:17: loop.rate_hz: expected a number, found \"fast\""));
  EXPECT_EQ(error_of("name: {first: t}\n"), at("1:7: name: expected a string, found a map"));
  EXPECT_EQ(error_of("name: t\nloop: 200\n"), at("2:7: loop: expected a map, found \"200\""));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  - {protocol: dynamixel2, port: /dev/ttyUSB0}
)"),
            at("4:3: buses: expected a map, found a list"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0, baud: 1e6}
)"),
            at("4:55: buses.b.baud: expected an integer, found \"1e6\""));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0, sim: {wire_time: yes}}
)"),
            at("4:66: buses.b.sim.wire_time: expected true or false, found \"yes\""));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: one}
)"),
            at("8:28: joints.j1.actuator.id: expected an integer, found \"one\""));
}

// ---------------------------------------------------------- numbers in range

TEST_F(RobotConfigTest, LoopRateOutOfRange) {
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 0}\n"),
            at("2:17: loop.rate_hz: expected a number from 1 to 10000, found \"0\""));
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 20000}\n"),
            at("2:17: loop.rate_hz: expected a number from 1 to 10000, found \"20000\""));
}

TEST_F(RobotConfigTest, SafetyOutOfRange) {
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 0}\n"),
            at("3:30: safety.watchdog_timeout_s: expected a positive number, found \"0\""));
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\nsafety: {start_ramp_s: 61}\n"),
            at("3:24: safety.start_ramp_s: expected a number from 0 to 60, found \"61\""));
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\nsafety: {stop_ramp_s: -1}\n"),
            at("3:23: safety.stop_ramp_s: expected a number from 0 to 60, found \"-1\""));
}

TEST_F(RobotConfigTest, BusNumbersOutOfRange) {
  const std::string head =
      "name: t\nloop: {rate_hz: 100}\nbuses:\n  b:\n    protocol: dynamixel2\n"
      "    port: /dev/ttyUSB0\n";
  EXPECT_EQ(error_of(head + "    baud: 0\n"),
            at("7:11: buses.b.baud: expected an integer from 9600 to 10500000, found \"0\""));
  EXPECT_EQ(error_of(head + "    baud: 12000000\n"),
            at("7:11: buses.b.baud: expected an integer from 9600 to 10500000, found "
               "\"12000000\""));
  EXPECT_EQ(error_of(head + "    timeout_ms: 0\n"),
            at("7:17: buses.b.timeout_ms: expected a number greater than 0 and less than 1000, "
               "found \"0\""));
  EXPECT_EQ(error_of(head + "    timeout_ms: 1000\n"),
            at("7:17: buses.b.timeout_ms: expected a number greater than 0 and less than 1000, "
               "found \"1000\""));
  EXPECT_EQ(error_of(head + "    sim: {time_constant_s: 0}\n"),
            at("7:28: buses.b.sim.time_constant_s: expected a number from 0.0001 to 10, found "
               "\"0\""));
  EXPECT_EQ(error_of(head + "    sim: {max_speed_dps: -330}\n"),
            at("7:26: buses.b.sim.max_speed_dps: expected a number from 0.01 to 100000, found "
               "\"-330\""));
  EXPECT_EQ(error_of(head + "    sim: {return_delay_us: 600}\n"),
            at("7:28: buses.b.sim.return_delay_us: expected an integer from 0 to 508, found "
               "\"600\""));
}

// ----------------------------------------------------------- missing keys

TEST_F(RobotConfigTest, MissingRequiredKeys) {
  EXPECT_EQ(error_of("loop: {rate_hz: 100}\n"), at("1:1: name: required key is missing"));
  EXPECT_EQ(error_of("name: t\n"), at("1:1: loop: required key is missing"));
  EXPECT_EQ(error_of("name: t\nloop: {}\n"), at("2:7: loop.rate_hz: required key is missing"));
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\n"), at("1:1: buses: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {port: /dev/ttyUSB0}
)"),
            at("4:6: buses.b.protocol: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2}
)"),
            at("4:6: buses.b.port: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
)"),
            at("1:1: joints: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    actuator: {bus: b, id: 1}
)"),
            at("7:5: joints.j1.limits: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, velocity_dps: 100, acceleration_dps2: 1000}
)"),
            at("7:13: joints.j1.limits.max_deg: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
)"),
            at("7:5: joints.j1.actuator: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {id: 1}
)"),
            at("8:15: joints.j1.actuator.bus: required key is missing"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b}
)"),
            at("8:15: joints.j1.actuator.id: required key is missing"));
  std::string no_motion = kMinimal;
  no_motion.erase(no_motion.find("motion:"));
  EXPECT_EQ(error_of(no_motion), at("1:1: motion: required key is missing"));
  std::string no_file = kMinimal;
  no_file.replace(no_file.find(", file: ../gaits/gait.yaml"), 26, "");
  EXPECT_EQ(error_of(no_file), at("9:9: motion.file: required key is missing"));
}

TEST_F(RobotConfigTest, MissingRobotFile) {
  const std::string path = (dir_ / "nope.yaml").string();
  try {
    (void)load_robot_config(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": cannot open file: No such file or directory");
  }
}

TEST_F(RobotConfigTest, EmptyName) {
  EXPECT_EQ(error_of("name: \"\"\n"), at("1:7: name: expected a robot name, found \"\""));
}

// ------------------------------------------------------------ buses, joints

TEST_F(RobotConfigTest, EmptyBusesAndJoints) {
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\nbuses: {}\n"),
            at("3:8: buses: expected at least one bus, found an empty map"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints: {}
)"),
            at("5:9: joints: expected at least one joint, found an empty map"));
}

TEST_F(RobotConfigTest, UnknownProtocol) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: modbus, port: /dev/ttyUSB0}
)"),
            at("4:17: buses.b.protocol: unknown protocol \"modbus\" (supported: dynamixel2, mit, "
               "cia402, maestro, modbus-tcp, modbus-rtu, feetech_sts, feetech_scs)"));
}

TEST_F(RobotConfigTest, TwoBusesOnOnePort) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  front: {protocol: dynamixel2, port: /dev/ttyUSB0}
  back: {protocol: dynamixel2, port: /dev/ttyUSB0}
)"),
            at("5:38: buses.back.port: port \"/dev/ttyUSB0\" is already used by bus front"));
}

TEST_F(RobotConfigTest, DuplicateBusAndJointNames) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
  b: {protocol: dynamixel2, port: /dev/ttyUSB1}
)"),
            at("5:3: buses.b: duplicate key"));
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1}
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 2}
)"),
            at("9:3: joints.j1: duplicate key"));
}

TEST_F(RobotConfigTest, DeviceIdOutOfRange) {
  const std::string head = R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
)";
  EXPECT_EQ(error_of(head + "    actuator: {bus: b, id: 253}\n"),
            at("8:28: joints.j1.actuator.id: expected a device id from 0 to 252 for dynamixel2, "
               "found \"253\""));
  EXPECT_EQ(error_of(head + "    actuator: {bus: b, id: -1}\n"),
            at("8:28: joints.j1.actuator.id: expected a device id from 0 to 252 for dynamixel2, "
               "found \"-1\""));
}

TEST_F(RobotConfigTest, DuplicateDeviceIdOnABus) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  knee:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 3}
  ankle:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 3}
)"),
            at("11:28: joints.ankle.actuator.id: device id 3 is already used by joint knee on "
               "bus b"));
}

TEST_F(RobotConfigTest, JointOnAnUndefinedBus) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  legs: {protocol: dynamixel2, port: /dev/ttyUSB0}
  neck: {protocol: dynamixel2, port: /dev/ttyUSB1}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: leg, id: 1}
)"),
            at("9:21: joints.j1.actuator.bus: no bus named \"leg\" (defined buses: legs, neck)"));
}

TEST_F(RobotConfigTest, BusWithoutJoints) {
  EXPECT_EQ(error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  legs: {protocol: dynamixel2, port: /dev/ttyUSB0}
  neck: {protocol: dynamixel2, port: /dev/ttyUSB1}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: legs, id: 1}
)"),
            at("5:3: buses.neck: no joint is bound to this bus (bind joints with actuator.bus: "
               "neck, or remove the bus)"));
}

// ----------------------------------------------------------------- limits

const char* const kLimitsHead = R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: dynamixel2, port: /dev/ttyUSB0}
joints:
  j1:
)";

TEST_F(RobotConfigTest, MinNotBelowMax) {
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: 10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"),
            at("7:36: joints.j1.limits.max_deg: expected a value greater than min_deg (10), "
               "found \"10\""));
}

TEST_F(RobotConfigTest, HomeOutsideLimits) {
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    home_deg: 12.5\n"),
            at("8:15: joints.j1.home_deg: limits contradict the home pose: expected home_deg "
               "within min_deg..max_deg (-10..10), found \"12.5\""));
  // Without home_deg the home pose is 0, which these limits exclude.
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: 10, max_deg: 90, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1}\n"),
            at("7:5: joints.j1.home_deg: limits contradict the home pose: home_deg defaults to 0, "
               "outside min_deg..max_deg (10..90); set home_deg inside the limits"));
}

TEST_F(RobotConfigTest, VelocityAndAccelerationMustBePositive) {
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 0, "
                     "acceleration_dps2: 1000}\n"),
            at("7:55: joints.j1.limits.velocity_dps: expected a number from 0.01 to 5000, found "
               "\"0\""));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: -5}\n"),
            at("7:79: joints.j1.limits.acceleration_dps2: expected a number from 0.01 to 1e+06, "
               "found \"-5\""));
}

TEST_F(RobotConfigTest, LimitsOutsideTheServoRange) {
  // 200 deg from the centre is past the end of a 0..4095 turn.
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 200, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1}\n"),
            at("7:37: joints.j1.limits.max_deg: 200 deg maps to tick 4324 (zero_ticks 2048, "
               "direction 1, 4096 ticks/rev), outside the dynamixel2 position range 0..4095"));
  // Mirrored with an off-centre zero: the lower limit lands above the top.
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -90, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, zero_ticks: 3500, direction: -1}\n"),
            at("7:23: joints.j1.limits.min_deg: -90 deg maps to tick 4524 (zero_ticks 3500, "
               "direction -1, 4096 ticks/rev), outside the dynamixel2 position range 0..4095"));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -90, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, ticks_per_rad: 2000}\n"),
            at("7:23: joints.j1.limits.min_deg: -90 deg maps to tick -1094 (zero_ticks 2048, "
               "direction 1, 2000 ticks/rad), outside the dynamixel2 position range 0..4095"));
}

// --------------------------------------------------------------- actuator

TEST_F(RobotConfigTest, AMultiTurnJointSpansTurnsAndTheKeyIsABoolean) {
  // 200 deg: past one turn, within extended position mode's +-256 turns.
  const std::string limits =
      "    limits: {min_deg: -10, max_deg: 200, velocity_dps: 100, acceleration_dps2: 1000}\n";
  EXPECT_EQ(error_of(std::string(kLimitsHead) + limits +
                     "    actuator: {bus: b, id: 1, multi_turn: true}\n"),
            at("1:1: motion: required key is missing"));  // the joint is valid
  EXPECT_EQ(error_of(std::string(kLimitsHead) + limits +
                     "    actuator: {bus: b, id: 1, multi_turn: yes}\n"),
            at("8:43: joints.j1.actuator.multi_turn: expected true or false, found \"yes\""));
  EXPECT_EQ(error_of(std::string(kLimitsHead) + limits +
                     "    actuator: {bus: b, id: 1, multi_turn: true, ticks_per_rev: 16000000}\n"),
            at("7:37: joints.j1.limits.max_deg: 200 deg maps to tick 8890937 (zero_ticks 2048, "
               "direction 1, 1.6e+07 ticks/rev), outside the dynamixel2 extended (multi_turn) "
               "position range -1048575..1048575"));
}

TEST_F(RobotConfigTest, DirectionMustBePlusOrMinusOne) {
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, direction: 0}\n"),
            at("8:42: joints.j1.actuator.direction: expected 1 or -1 (-1 for a mirrored servo), "
               "found \"0\""));
}

TEST_F(RobotConfigTest, TicksPerRevOrPerRadNotBoth) {
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, ticks_per_rev: 4096, ticks_per_rad: 651.9}\n"),
            at("8:67: joints.j1.actuator.ticks_per_rad: give either ticks_per_rev or "
               "ticks_per_rad, not both"));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, ticks_per_rev: 0}\n"),
            at("8:46: joints.j1.actuator.ticks_per_rev: expected a number from 16 to 1e+08, "
               "found \"0\""));
}

// ----------------------------------------------------------------- motion

TEST_F(RobotConfigTest, UnknownMotionType) {
  std::string text = kMinimal;
  text.replace(text.find("type: gait"), 10, "type: keyframes");
  EXPECT_EQ(error_of(text), at("9:16: motion.type: unknown motion type \"keyframes\" (supported: "
                               "gait, head, show, layers)"));
}

TEST_F(RobotConfigTest, MotionFileMissing) {
  std::string text = kMinimal;
  text.replace(text.find("gait.yaml"), 9, "walk.yaml");
  const std::string resolved = (dir_ / "robots" / ".." / "gaits" / "walk.yaml").string();
  EXPECT_EQ(error_of(text),
            at("9:28: motion.file: file not found: \"../gaits/walk.yaml\" (resolved against the "
               "robot file's folder to \"" +
               resolved + "\")"));
}

TEST_F(RobotConfigTest, MotionFileIsAFolder) {
  std::string text = kMinimal;
  text.replace(text.find("../gaits/gait.yaml"), 18, "../gaits");
  const std::string resolved = (dir_ / "robots" / ".." / "gaits").string();
  EXPECT_EQ(error_of(text),
            at("9:28: motion.file: \"../gaits\" (resolved against the robot file's folder to \"" +
               resolved + "\") is a directory"));
}

TEST_F(RobotConfigTest, MotionFileIsADevice) {
  std::string text = kMinimal;
  text.replace(text.find("../gaits/gait.yaml"), 18, "/dev/zero");
  EXPECT_EQ(error_of(text),
            at("9:28: motion.file: \"/dev/zero\" is not a regular file (character device)"));
}

TEST_F(RobotConfigTest, MotionFileIsAFifo) {
  const fs::path fifo = dir_ / "gaits" / "pipe.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string text = kMinimal;
  text.replace(text.find("../gaits/gait.yaml"), 18, "../gaits/pipe.yaml");
  // Nothing writes to the FIFO: opening it would block.
  EXPECT_EQ(error_of(text),
            at("9:28: motion.file: \"../gaits/pipe.yaml\" (resolved against the robot file's "
               "folder to \"" +
               (dir_ / "robots" / ".." / "gaits" / "pipe.yaml").string() +
               "\") is not a regular file (FIFO)"));
}

}  // namespace
}  // namespace animrt

namespace animrt {
namespace {

// ------------------------------------------------- plausible ranges (load time)

TEST_F(RobotConfigTest, ImplausibleNumbersAreRejectedAtTheirKey) {
  const std::string limits =
      "    limits: {min_deg: -10, max_deg: 10, velocity_dps: VEL, acceleration_dps2: ACC}\n"
      "    actuator: {bus: b, id: 1}\n";
  const auto with = [&](const std::string& vel, const std::string& acc) {
    std::string text = std::string(kLimitsHead) + limits;
    text.replace(text.find("VEL"), 3, vel);
    text.replace(text.find("ACC"), 3, acc);
    return text;
  };
  EXPECT_EQ(error_of(with("1e-300", "1000")),
            at("7:55: joints.j1.limits.velocity_dps: expected a number from 0.01 to 5000, found "
               "\"1e-300\""));
  EXPECT_EQ(error_of(with("6000", "1000")),
            at("7:55: joints.j1.limits.velocity_dps: expected a number from 0.01 to 5000, found "
               "\"6000\""));
  EXPECT_EQ(error_of(with("100", "1e9")),
            at("7:79: joints.j1.limits.acceleration_dps2: expected a number from 0.01 to 1e+06, "
               "found \"1e9\""));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -1e9, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"),
            at("7:23: joints.j1.limits.min_deg: expected a number from -3600 to 3600, found "
               "\"-1e9\""));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, ticks_per_rev: 1e-300}\n"),
            at("8:46: joints.j1.actuator.ticks_per_rev: expected a number from 16 to 1e+08, "
               "found \"1e-300\""));
  EXPECT_EQ(error_of(std::string(kLimitsHead) +
                     "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
                     "acceleration_dps2: 1000}\n"
                     "    actuator: {bus: b, id: 1, ticks_per_rad: 1e-300}\n"),
            at("8:46: joints.j1.actuator.ticks_per_rad: expected a number from 2.54648 to "
               "1.59155e+07, found \"1e-300\""));
}

TEST_F(RobotConfigTest, WatchdogAtMostFiveSeconds) {
  EXPECT_EQ(error_of("name: t\nloop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 1e30}\n"),
            at("3:30: safety.watchdog_timeout_s: expected at most 5 s, found \"1e30\""));
}

TEST_F(RobotConfigTest, BusTimeoutMustBeBelowTheWatchdog) {
  std::string text = kMinimal;
  text.replace(text.find("port: /dev/ttyUSB0}"), 19, "port: /dev/ttyUSB0, timeout_ms: 999}");
  text.replace(text.find("loop: {rate_hz: 100}"), 20,
               "loop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 0.1}");
  EXPECT_EQ(error_of(text),
            at("5:61: buses.b.timeout_ms: expected a bus timeout below the watchdog "
               "(safety.watchdog_timeout_s 0.1 s), found \"999\" ms"));
  // Without a safety section the default watchdog (0.1 s) applies.
  text = kMinimal;
  text.replace(text.find("port: /dev/ttyUSB0}"), 19, "port: /dev/ttyUSB0, timeout_ms: 150}");
  EXPECT_EQ(error_of(text),
            at("4:61: buses.b.timeout_ms: expected a bus timeout below the watchdog "
               "(safety.watchdog_timeout_s 0.1 s, the default), found \"150\" ms"));
}

TEST_F(RobotConfigTest, LoopRateTheBusCannotCarry) {
  const fs::path copy = dir_ / "robots" / "quadruped.yaml";
  std::string text = read_file(kSourceRoot + "/configs/robots/quadruped.yaml");
  write_file(dir_ / "gaits" / "walk.yaml", "# stand-in\n");
  write_file(dir_ / "models" / "quadruped.xml", "<!-- stand-in -->\n");
  const auto rate = text.find("rate_hz: 200");
  ASSERT_NE(rate, std::string::npos);
  text.replace(rate, 12, "rate_hz: 10000");
  text.replace(text.find("watchdog_timeout_s: 0.1"), 23, "watchdog_timeout_s: 0.01");
  write_file(copy, text);
  // 12 servos: Sync Write 74 bytes, Sync Read 26, 12 answers of 15: 280
  // bytes of 10 bits at 1 Mbaud.
  const std::string line =
      std::to_string(std::count(text.begin(), text.begin() + static_cast<long>(rate), '\n') + 1);
  try {
    (void)load_robot_config(copy.string());
    ADD_FAILURE() << "rate accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              copy.string() + ":" + line +
                  ":12: loop.rate_hz: bus legs (dynamixel2, 12 devices at 1000000 baud) needs "
                  "about 2.8 ms of wire time per cycle, longer than the 0.1 ms loop period; "
                  "expected at most 357 Hz, found \"10000\"");
  }
  // 350 Hz fits.
  text.replace(text.find("rate_hz: 10000"), 14, "rate_hz: 350");
  write_file(copy, text);
  EXPECT_DOUBLE_EQ(load_robot_config(copy.string()).rate_hz, 350.0);
}

TEST_F(RobotConfigTest, NewSafetyKeysAreReadInTheirUnits) {
  std::string text = kMinimal;
  text.replace(text.find("loop: {rate_hz: 100}"), 20,
               "loop: {rate_hz: 100}\nsafety: {start_ramp_max_s: 30, stop_deadline_s: 8, "
               "following_error_deg: 10, following_error_mm: 5, following_error_window_s: 0.25}");
  const RobotConfig c = load(text);
  EXPECT_DOUBLE_EQ(c.safety.start_ramp_max_s, 30.0);
  EXPECT_DOUBLE_EQ(c.safety.stop_deadline_s, 8.0);
  EXPECT_DOUBLE_EQ(c.safety.following_error_rad, deg_to_rad(10.0));
  EXPECT_DOUBLE_EQ(c.safety.following_error_m, 0.005);
  EXPECT_DOUBLE_EQ(c.safety.following_error_window_s, 0.25);
}

TEST_F(RobotConfigTest, NewSafetyKeysOutOfRange) {
  const std::string head = "name: t\nloop: {rate_hz: 100}\nsafety: {";
  EXPECT_EQ(error_of(head + "start_ramp_s: 5, start_ramp_max_s: 4}\n"),
            at("3:45: safety.start_ramp_max_s: expected more than start_ramp_s (5 s), found "
               "\"4\""));
  EXPECT_EQ(error_of(head + "start_ramp_max_s: 121}\n"),
            at("3:28: safety.start_ramp_max_s: expected a number from 0 to 120, found \"121\""));
  EXPECT_EQ(error_of(head + "start_ramp_s: 25}\n"),
            at("3:24: safety.start_ramp_s: expected less than start_ramp_max_s (20 s by "
               "default); set start_ramp_max_s too"));
  EXPECT_EQ(error_of(head + "stop_ramp_s: 3, stop_deadline_s: 2}\n"),
            at("3:43: safety.stop_deadline_s: expected at least stop_ramp_s (3 s), found \"2\""));
  EXPECT_EQ(error_of(head + "stop_deadline_s: 31}\n"),
            at("3:27: safety.stop_deadline_s: expected a number from 0 to 30, found \"31\""));
  EXPECT_EQ(error_of(head + "stop_ramp_s: 10}\n"),
            at("3:23: safety.stop_ramp_s: expected at most stop_deadline_s (6 s by default); "
               "set stop_deadline_s too"));
  EXPECT_EQ(error_of(head + "following_error_deg: 0.1}\n"),
            at("3:31: safety.following_error_deg: expected a number from 0.5 to 180, found "
               "\"0.1\""));
  EXPECT_EQ(error_of(head + "following_error_mm: 0}\n"),
            at("3:30: safety.following_error_mm: expected a number from 0.1 to 1000, found "
               "\"0\""));
  EXPECT_EQ(error_of(head + "following_error_window_s: 0.015}\n"),
            at("3:36: safety.following_error_window_s: expected at least two loop periods "
               "(0.02 s at loop.rate_hz 100), found \"0.015\""));
  EXPECT_EQ(error_of(head + "following_error_window_s: 6}\n"),
            at("3:36: safety.following_error_window_s: expected a number from 0 to 5, found "
               "\"6\""));
}

TEST_F(RobotConfigTest, HealthLimitsAndTheSimulatedHealthAreRead) {
  std::string text = kMinimal;
  text.replace(text.find("loop: {rate_hz: 100}"), 20,
               "loop: {rate_hz: 100}\nsafety:\n  health: {temperature_warn_c: 60, "
               "temperature_fault_c: 70, voltage_warn_v: 11, voltage_fault_v: 10, "
               "stall_current_a: 1.2, stall_time_s: 0.3, stall_error_deg: 4, error_bits: warn}");
  text.replace(text.find("b: {protocol: dynamixel2, port: /dev/ttyUSB0}"), 45,
               "b:\n    protocol: dynamixel2\n    port: /dev/ttyUSB0\n    health: packed\n"
               "    health_limits: {temperature_fault_c: 55}\n"
               "    sim:\n      health: {ambient_c: 30, supply_v: 11.1}\n"
               "      inject:\n        - {id: 1, at_s: 2, temperature_c: 80}\n"
               "        - {id: 1, at_s: 3, blocked: true}");
  const RobotConfig c = load(text);
  const HealthLimits& h = c.safety.health;
  EXPECT_DOUBLE_EQ(h.temperature_warn_c, 60.0);
  EXPECT_DOUBLE_EQ(h.temperature_fault_c, 70.0);
  EXPECT_DOUBLE_EQ(h.voltage_warn_v, 11.0);
  EXPECT_DOUBLE_EQ(h.voltage_fault_v, 10.0);
  EXPECT_DOUBLE_EQ(h.stall_current_a, 1.2);
  EXPECT_DOUBLE_EQ(h.stall_time_s, 0.3);
  EXPECT_DOUBLE_EQ(h.stall_error_rad, deg_to_rad(4.0));
  EXPECT_EQ(h.error_bits, HealthLimits::Bits::warn);
  const BusConfig& bus = c.buses[0];
  ASSERT_TRUE(bus.health_limits.has_value());
  EXPECT_DOUBLE_EQ(bus.health_limits->temperature_fault_c, 55.0);
  EXPECT_TRUE(std::isnan(bus.health_limits->temperature_warn_c));
  EXPECT_EQ(dxl::bus_options(bus).health, dxl::HealthRead::packed);
  EXPECT_DOUBLE_EQ(bus.sim.health.ambient_c, 30.0);
  EXPECT_DOUBLE_EQ(bus.sim.health.supply_v, 11.1);
  ASSERT_EQ(bus.sim.health.inject.size(), 2u);
  EXPECT_EQ(bus.sim.health.inject[0].kind, SimHealthInjection::Kind::temperature);
  EXPECT_DOUBLE_EQ(bus.sim.health.inject[0].value, 80.0);
  EXPECT_EQ(bus.sim.health.inject[1].kind, SimHealthInjection::Kind::blocked);
  EXPECT_DOUBLE_EQ(bus.sim.health.inject[1].at_s, 3.0);
}

TEST_F(RobotConfigTest, ADevicesOwnHealthLimitsOverrideItsBussKeyByKey) {
  std::string text = kMinimal;
  text.replace(text.find("loop: {rate_hz: 100}"), 20,
               "loop: {rate_hz: 100}\nsafety:\n  health: {temperature_warn_c: 60, "
               "temperature_fault_c: 70, voltage_warn_v: 11, voltage_fault_v: 10}");
  text.replace(text.find("    actuator: {bus: b, id: 1}"), 29,
               "    actuator: {bus: b, id: 1, health_limits: {temperature_fault_c: 50, "
               "temperature_warn_c: 45}}\n"
               "  j2:\n"
               "    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: "
               "1000}\n"
               "    actuator: {bus: b, id: 2}");
  const RobotConfig c = load(text);
  const auto& own = c.buses[0].actuators[0].health_limits;
  ASSERT_TRUE(own.has_value());
  EXPECT_DOUBLE_EQ(own->temperature_fault_c, 50.0);
  EXPECT_DOUBLE_EQ(own->temperature_warn_c, 45.0);
  EXPECT_DOUBLE_EQ(own->voltage_fault_v, 10.0);  // the rest from safety.health
  EXPECT_FALSE(c.buses[0].actuators[1].health_limits.has_value());
  std::vector<const BusConfig*> buses{&c.buses[0]};
  const RobotModel m = make_robot_model(c, buses);
  EXPECT_DOUBLE_EQ(m.buses[0].health_of(0).temperature_fault_c, 50.0);
  EXPECT_DOUBLE_EQ(m.buses[0].health_of(1).temperature_fault_c, 70.0);

  // A warning the device raises past the fault it inherits.
  text.replace(text.find("temperature_fault_c: 50, temperature_warn_c: 45"), 47,
               "temperature_warn_c: 75");
  EXPECT_EQ(error_of(text),
            at("10:67: joints.j1.actuator.health_limits.temperature_warn_c: expected less than "
               "temperature_fault_c (70), found \"75\""));
}

TEST_F(RobotConfigTest, BadHealthKeysNameTheirPlace) {
  const std::string head = "name: t\nloop: {rate_hz: 100}\nsafety:\n  health: {";
  EXPECT_EQ(error_of(head + "temperature_warn_c: 70, temperature_fault_c: 60}\n"),
            at("4:57: safety.health.temperature_fault_c: expected more than temperature_warn_c "
               "(70), found \"60\""));
  EXPECT_EQ(error_of(head + "voltage_warn_v: 10, voltage_fault_v: 11}\n"),
            at("4:49: safety.health.voltage_fault_v: expected less than voltage_warn_v (10), "
               "found \"11\""));
  EXPECT_EQ(error_of(head + "error_bits: maybe}\n"),
            at("4:24: safety.health.error_bits: expected fault, warn or ignore, found \"maybe\""));
  EXPECT_EQ(error_of(head + "stall_time_s: 0.001}\n"),
            at("4:26: safety.health.stall_time_s: expected at least two loop periods (0.02 s at "
               "loop.rate_hz 100), found \"0.001\""));
  EXPECT_EQ(error_of(head + "temp_c: 1}\n"),
            at("4:12: safety.health.temp_c: unknown key (expected one of: temperature_warn_c, "
               "temperature_fault_c, voltage_warn_v, voltage_fault_v, stall_current_a, "
               "stall_time_s, stall_error_deg, error_bits)"));
  std::string text = kMinimal;
  text.replace(text.find("b: {protocol: dynamixel2, port: /dev/ttyUSB0}"), 45,
               "b:\n    protocol: dynamixel2\n    port: /dev/ttyUSB0\n    health: always\n");
  EXPECT_EQ(error_of(text), at("7:13: buses.b.health: expected off, packed or round_robin, found "
                               "\"always\""));
  text = kMinimal;
  text.replace(text.find("b: {protocol: dynamixel2, port: /dev/ttyUSB0}"), 45,
               "b:\n    protocol: dynamixel2\n    port: /dev/ttyUSB0\n    sim:\n      inject:\n"
               "        - {id: 1, at_s: 2, temperature_c: 80, blocked: true}\n");
  EXPECT_EQ(error_of(text), at("9:11: buses.b.sim.inject[0]: expected exactly one of "
                               "temperature_c, blocked, supply_v, hardware_error, found 2"));
  // A fault injected into a servo the bus does not have would never come.
  text.replace(text.find("{id: 1, at_s: 2, temperature_c: 80, blocked: true}"), 50,
               "{id: 9, at_s: 2, temperature_c: 80}");
  EXPECT_EQ(error_of(text), at("9:16: buses.b.sim.inject[0].id: no device on bus b has id 9 (its "
                               "devices: 1)"));
}

TEST(RobotConfigWatchdog, MustCoverTwoLoopPeriods) {
  const std::string dir = ::testing::TempDir() + "/watchdog_test";
  std::filesystem::create_directories(dir);
  const std::string gait = std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/walk.yaml";
  const std::string path = dir + "/robot.yaml";
  std::ofstream(path) << "name: r\nloop: {rate_hz: 100}\nsafety: {watchdog_timeout_s: 0.015}\n"
                         "buses: {b: {protocol: dynamixel2, port: /dev/null}}\n"
                         "joints: {j: {limits: {min_deg: -1, max_deg: 1, velocity_dps: 1, "
                         "acceleration_dps2: 1}, actuator: {bus: b, id: 1}}}\n"
                         "motion: {type: gait, file: " +
                             gait + "}\n";
  try {
    load_robot_config(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path +
                  ":3:30: safety.watchdog_timeout_s: expected at least two loop periods "
                  "(0.02 s at loop.rate_hz 100), found \"0.015\"");
  }
}

// ------------------------------------------------------- dynamixel2 options

TEST_F(RobotConfigTest, DynamixelFastReadModelAndFirmwareKeys) {
  const RobotConfig c = load(R"(name: t
loop: {rate_hz: 100}
buses:
  b:
    protocol: dynamixel2
    port: /dev/ttyUSB0
    fast_read: "on"
    model: XM430-W350
    sim: {firmware_version: 46}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1}
  j2:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 2, model: XH540-W270}
motion: {type: gait, file: ../gaits/gait.yaml}
)");
  ASSERT_EQ(c.buses.size(), 1u);
  EXPECT_EQ(dxl::bus_options(c.buses[0]).fast_read, dxl::FastRead::on);
  EXPECT_EQ(c.buses[0].sim.firmware_version, 46);
  ASSERT_EQ(c.buses[0].actuators.size(), 2u);
  EXPECT_EQ(dxl::device_options(c.buses[0].actuators[0]).model_number, 1020);  // the bus's
  EXPECT_EQ(dxl::device_options(c.buses[0].actuators[1]).model_number, 1100);  // its own
  // Defaults: auto, no model.
  const RobotConfig d = load(kMinimal);
  EXPECT_EQ(dxl::bus_options(d.buses[0]).fast_read, dxl::FastRead::automatic);
  EXPECT_EQ(dxl::device_options(d.buses[0].actuators[0]).model_number, 0);
}

TEST_F(RobotConfigTest, DynamixelBadFastReadOrModelIsNamed) {
  const std::string head = "name: t\nloop: {rate_hz: 100}\nbuses:\n";
  const std::string tail =
      "joints:\n  j1:\n    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, "
      "acceleration_dps2: 1000}\n    actuator: {bus: b, id: 1";
  const std::string motion = "}\nmotion: {type: gait, file: ../gaits/gait.yaml}\n";
  EXPECT_EQ(error_of(head + "  b: {protocol: dynamixel2, port: /dev/ttyUSB0, fast_read: fast}\n" +
                     tail + motion),
            at("4:60: buses.b.fast_read: expected auto, on or off, found \"fast\""));
  const std::string names = dxl::x_model_names();
  EXPECT_EQ(error_of(head + "  b: {protocol: dynamixel2, port: /dev/ttyUSB0, model: XM430}\n" +
                     tail + motion),
            at("4:56: buses.b.model: expected a Dynamixel X-series model (" + names +
               "), found \"XM430\""));
  EXPECT_EQ(error_of(head + "  b: {protocol: dynamixel2, port: /dev/ttyUSB0}\n" + tail +
                     ", model: AX-12A" + motion),
            at("8:38: joints.j1.actuator.model: expected a Dynamixel X-series model (" + names +
               "), found \"AX-12A\""));
  EXPECT_NE(error_of(head +
                     "  b: {protocol: dynamixel2, port: /dev/ttyUSB0, sim: {firmware_version: "
                     "0}}\n" +
                     tail + motion)
                .find("buses.b.sim.firmware_version"),
            std::string::npos);
}

// Every layer is sampled every cycle: 16 load, 17 are refused at the list.
TEST_F(RobotConfigTest, MotionLayersAreAtMostSixteen) {
  std::string base = kMinimal;
  base = base.substr(0, base.find("motion:"));
  const auto layers = [&](int n) {
    std::string text = base + "motion:\n  type: layers\n  layers:\n";
    for (int i = 0; i < n; ++i) text += "    - {type: gait, file: ../gaits/gait.yaml}\n";
    return text;
  };
  EXPECT_EQ(error_of(layers(16)), "no error");
  EXPECT_EQ(error_of(layers(17)),
            at("12:5: motion.layers: expected at most 16 motion sources, found 17"));
}

// ------------------------------------------------------- device watchdog

TEST_F(RobotConfigTest, DynamixelBusWatchdogDefaultsToAFewLoopPeriods) {
  // 100 Hz: 5 periods are 50 ms, so the floor of 100 ms: 5 units of 20 ms.
  EXPECT_EQ(dxl::bus_options(load(kMinimal).buses[0]).bus_watchdog, 5);
  // 10 Hz: 5 periods are 500 ms: 25 units.
  std::string slow = kMinimal;
  slow.replace(slow.find("rate_hz: 100"), 12, "rate_hz: 10");
  EXPECT_EQ(dxl::bus_options(load(slow).buses[0]).bus_watchdog, 25);
  // 30 Hz: 5 periods are 166.7 ms, rounded up to 180 ms: 9 units.
  std::string mid = kMinimal;
  mid.replace(mid.find("rate_hz: 100"), 12, "rate_hz: 30");
  EXPECT_EQ(dxl::bus_options(load(mid).buses[0]).bus_watchdog, 9);
  // 1 kHz: 5 periods are 5 ms, so 100 ms: 5 units.
  std::string fast = kMinimal;
  fast.replace(fast.find("rate_hz: 100"), 12, "rate_hz: 1000");
  EXPECT_EQ(dxl::bus_options(load(fast).buses[0]).bus_watchdog, 5);
}

TEST_F(RobotConfigTest, DynamixelBusWatchdogKey) {
  const auto with = [&](const std::string& value) {
    std::string text = kMinimal;
    text.replace(text.find("port: /dev/ttyUSB0}"), 19,
                 "port: /dev/ttyUSB0, device_watchdog_ms: " + value + "}");
    return text;
  };
  EXPECT_EQ(dxl::bus_options(load(with("off")).buses[0]).bus_watchdog, 0);
  EXPECT_EQ(dxl::bus_options(load(with("0")).buses[0]).bus_watchdog, 0);
  EXPECT_EQ(dxl::bus_options(load(with("41")).buses[0]).bus_watchdog, 3);  // rounded up
  EXPECT_EQ(dxl::bus_options(load(with("2540")).buses[0]).bus_watchdog, 127);
  const std::string expected =
      "buses.b.device_watchdog_ms: expected off, 0, or milliseconds from 20 to 2540 (Bus "
      "Watchdog, units of 20 ms), found ";
  EXPECT_EQ(error_of(with("2541")), at("4:69: " + expected + "\"2541\""));
  EXPECT_EQ(error_of(with("10")), at("4:69: " + expected + "\"10\""));
  EXPECT_EQ(error_of(with("-20")), at("4:69: " + expected + "\"-20\""));
  EXPECT_EQ(error_of(with("on")), at("4:69: " + expected + "\"on\""));
}

TEST_F(RobotConfigTest, DeviceWatchdogOnABusWithoutOneIsNamed) {
  const std::string error = error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: feetech_sts, port: /dev/ttyUSB0, device_watchdog_ms: 100}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, id: 1}
motion: {type: gait, file: ../gaits/gait.yaml}
)");
  EXPECT_NE(error.find(at("4:70: buses.b.device_watchdog_ms: ")), std::string::npos) << error;
  EXPECT_NE(error.find("no device-side watchdog"), std::string::npos) << error;
  // A register map that names no watchdog register.
  const std::string modbus = error_of(R"(name: t
loop: {rate_hz: 100}
buses:
  b: {protocol: modbus-tcp, port: 127.0.0.1:502, device_watchdog_ms: 100}
joints:
  j1:
    limits: {min_deg: -10, max_deg: 10, velocity_dps: 100, acceleration_dps2: 1000}
    actuator: {bus: b, slave: 1, map: )" +
                                      std::string(ANIMRT_SOURCE_DIR) +
                                      R"(/configs/modbus/position_drive.yaml}
motion: {type: gait, file: ../gaits/gait.yaml}
)");
  EXPECT_NE(modbus.find(at("4:70: buses.b.device_watchdog_ms: ")), std::string::npos) << modbus;
  EXPECT_NE(modbus.find("names no watchdog or timeout register"), std::string::npos) << modbus;
}

}  // namespace
}  // namespace animrt

namespace animrt {
namespace {

// ------------------------------------------------------------ IMUs and tilt

class RobotConfigImu : public RobotConfigTest {
 protected:
  std::string with(const std::string& extra) { return std::string(kMinimal) + extra; }
};

TEST_F(RobotConfigImu, AnImuAndTheTiltWatchAreRead) {
  const RobotConfig c = load(with(R"(imus:
  - {name: trunk, protocol: bno08x_rvc, port: /dev/ttyUSB1, stale_timeout_s: 0.05,
     mount: {yaw_deg: 90, roll_deg: 180},
     sim: {push_at_s: 1.5, push_axis: pitch, push_rate_deg_s: 120, push_to_deg: -85}}
safety: {tilt_limit_deg: 50, tilt_time_s: 0.3, on_tilt: torque_off}
)"));
  ASSERT_EQ(c.imus.size(), 1u);
  EXPECT_EQ(c.imus[0].name, "trunk");
  EXPECT_EQ(c.imus[0].port, "/dev/ttyUSB1");
  EXPECT_DOUBLE_EQ(c.imus[0].stale_timeout_s, 0.05);
  EXPECT_NEAR(c.imus[0].mount_ypr_rad[0], kPi / 2, 1e-12);
  EXPECT_NEAR(c.imus[0].mount_ypr_rad[2], kPi, 1e-12);
  EXPECT_TRUE(c.imus[0].sim_push.on);
  EXPECT_TRUE(c.imus[0].sim_push.pitch);
  EXPECT_NEAR(c.imus[0].sim_push.to_rad, -85 * kPi / 180, 1e-12);
  EXPECT_NEAR(c.safety.tilt_limit_rad, 50 * kPi / 180, 1e-12);
  EXPECT_DOUBLE_EQ(c.safety.tilt_time_s, 0.3);
  EXPECT_EQ(c.safety.on_tilt, SafetyConfig::OnTilt::torque_off);
}

TEST_F(RobotConfigImu, BadImusAreNamedWhereTheyAre) {
  EXPECT_EQ(error_of(with("imus:\n  - {name: trunk, protocol: mpu6050}\n")),
            at("11:29: imus[0].protocol: unknown IMU protocol \"mpu6050\" (supported: "
               "bno08x_rvc)"));
  EXPECT_NE(error_of(with("imus:\n  - {name: trunk, protocol: bno08x_rvc, rate_hz: 400}\n"))
                .find("imus[0].rate_hz: expected 100"),
            std::string::npos);
  EXPECT_NE(error_of(with("imus:\n  - {name: trunk, protocol: bno08x_rvc, stale_timeout_s: "
                          "0.01}\n"))
                .find("imus[0].stale_timeout_s: expected at least two"),
            std::string::npos);
  EXPECT_NE(error_of(with("safety: {on_tilt: ramp}\n")).find("safety.on_tilt: expected hold or"),
            std::string::npos);
}

TEST_F(RobotConfigImu, ASimulatedPartsLatencyMayBeAsShortAsALoopPeriod) {
  // A real part sends a frame when its fusion has computed it, not a report
  // period later; the simulated one can report no fresher than a lockstep
  // physics that is a loop period behind the clock.
  std::string text = with("imus:\n  - {name: trunk, protocol: bno08x_rvc, sim: {latency_ms: 5}}\n");
  text.replace(text.find("rate_hz: 100"), 12, "rate_hz: 200");
  const RobotConfig c = load(text);
  ASSERT_EQ(c.imus.size(), 1u);
  EXPECT_DOUBLE_EQ(c.imus[0].sim_latency_s, 0.005);
  text.replace(text.find("latency_ms: 5"), 13, "latency_ms: 4");
  EXPECT_NE(error_of(text).find("imus[0].sim.latency_ms: expected"), std::string::npos)
      << error_of(text);
}

TEST_F(RobotConfigImu, ATiltWatchWithoutAnImuIsRefused) {
  EXPECT_NE(error_of(with("safety: {tilt_limit_deg: 45}\n"))
                .find("safety.tilt_limit_deg: the tilt watch needs an IMU"),
            std::string::npos);
}

}  // namespace
}  // namespace animrt
