// Robot files with Feetech buses: the arm loads, and every Feetech key is
// checked with the file, line, column and key in the message.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "animrt/bridge/feetech/feetech_protocol.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {
namespace {

namespace fs = std::filesystem;

class FeetechConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("animrt_feetech_config_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "robots");
    fs::create_directories(dir_ / "gaits");
    std::ofstream(dir_ / "gaits" / "gait.yaml") << "# a gait\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path() const { return (dir_ / "robots" / "robot.yaml").string(); }

  // The robot file with `bus` and `actuator` spliced in (the bus keys from
  // line 7).
  std::string robot(const std::string& protocol, const std::string& bus_keys,
                    const std::string& actuator, const std::string& limits = "-90, max_deg: 90") {
    return "name: r\n"
           "loop: {rate_hz: 100}\n"
           "buses:\n"
           "  arm:\n"
           "    protocol: " +
           protocol +
           "\n"
           "    port: /dev/ttyUSB0\n" +
           bus_keys +
           "joints:\n"
           "  j:\n"
           "    limits: {min_deg: " +
           limits +
           ", velocity_dps: 90, acceleration_dps2: 900}\n"
           "    actuator: {bus: arm, " +
           actuator +
           "}\n"
           "motion: {type: gait, file: ../gaits/gait.yaml}\n";
  }

  std::string error_of(const std::string& text) {
    std::ofstream(path()) << text;
    try {
      (void)load_robot_config(path());
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  std::string at(const std::string& rest) const { return path() + ":" + rest; }

  fs::path dir_;
};

TEST_F(FeetechConfig, TheArmLoadsWithItsDefaults) {
  const RobotConfig config =
      load_robot_config(std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/arm_sts.yaml");
  ASSERT_EQ(config.buses.size(), 1u);
  const BusConfig& bus = config.buses[0];
  EXPECT_EQ(bus.protocol, "feetech_sts");
  EXPECT_EQ(bus.baud, 1'000'000);
  ASSERT_EQ(bus.actuators.size(), 6u);
  for (const ActuatorBinding& b : bus.actuators) {
    EXPECT_EQ(b.zero_ticks, 2048) << b.joint;
    EXPECT_NEAR(b.ticks_per_rad, 4096 / (2 * kPi), 1e-9) << b.joint;
  }
  EXPECT_EQ(bus.actuators[2].direction, -1);
}

TEST_F(FeetechConfig, ScsDefaultsToItsOwnScale) {
  std::ofstream(path()) << robot("feetech_scs", "", "id: 3", "-100, max_deg: 100");
  const RobotConfig config = load_robot_config(path());
  const ActuatorBinding& b = config.buses[0].actuators[0];
  EXPECT_EQ(b.zero_ticks, 512);
  EXPECT_NEAR(b.ticks_per_rad, 1024.0 / (300.0 * kPi / 180.0), 1e-9);
}

TEST_F(FeetechConfig, BadKeysAreNamedWithFileLineAndKey) {
  EXPECT_EQ(error_of(robot("feetech_sts", "    baud: 9600\n", "id: 1")),
            at("7:11: buses.arm.baud: expected a Feetech baud rate (1000000, 500000, 250000, "
               "128000, 115200, 76800, 57600 or 38400), found \"9600\""));
  EXPECT_EQ(error_of(robot("feetech_sts", "", "id: 254")),
            at("10:30: joints.j.actuator.id: expected a servo id from 0 to 253 for feetech_sts, "
               "found \"254\""));
  EXPECT_EQ(error_of(robot("feetech_sts", "    timeout_ms: 0\n", "id: 1")),
            at("7:17: buses.arm.timeout_ms: expected a number greater than 0 and less than "
               "1000, found \"0\""));
  // SCS: about 300 degrees of travel, so +-160 is out of reach.
  EXPECT_EQ(error_of(robot("feetech_scs", "", "id: 1", "-160, max_deg: 100")),
            at("9:23: joints.j.limits.min_deg: -160 deg maps to step -34 (zero_ticks 512, "
               "direction 1, 1228.8 ticks/rev), outside the feetech_scs position range 0..1023"));
  const std::string unknown = error_of(robot("feetech_sts", "    series: sts\n", "id: 1"));
  EXPECT_NE(unknown.find("7:5: buses.arm.series"), std::string::npos) << unknown;
  const std::string unknown_actuator = error_of(robot("feetech_sts", "", "id: 1, channel: 2"));
  EXPECT_NE(unknown_actuator.find("joints.j.actuator.channel"), std::string::npos)
      << unknown_actuator;
}

TEST_F(FeetechConfig, TheWireLimitRefusesALoopTheBusCannotCarry) {
  // 12 STS servos at 38400 baud: 160 bytes, about 41.7 ms a cycle.
  std::string text =
      "name: r\nloop: {rate_hz: 100}\nbuses:\n  arm: {protocol: feetech_sts, port: "
      "/dev/ttyUSB0, baud: 38400}\njoints:\n";
  for (int i = 1; i <= 12; ++i) {
    text += "  j" + std::to_string(i) +
            ":\n    limits: {min_deg: -90, max_deg: 90, velocity_dps: 90, acceleration_dps2: "
            "900}\n    actuator: {bus: arm, id: " +
            std::to_string(i) + "}\n";
  }
  text += "motion: {type: gait, file: ../gaits/gait.yaml}\n";
  const std::string e = error_of(text);
  EXPECT_NE(e.find("needs about 41.7 ms of wire time per cycle"), std::string::npos) << e;
  const Protocol* sts = find_protocol("feetech_sts");
  ASSERT_NE(sts, nullptr);
  BusConfig bus;
  bus.actuators.resize(6);
  EXPECT_EQ(sts->wire_bits_per_cycle(bus), 880.0);  // (8 + 18) + (8 + 6) + 6 * 8 bytes
  EXPECT_EQ(find_protocol("feetech_scs")->wire_bits_per_cycle(bus), 1220.0);  // 26 + 6 * 16
}

}  // namespace
}  // namespace animrt
