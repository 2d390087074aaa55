// The robot file's keys for homing a CiA 402 drive on its switches: the
// joint's `homing:` map (method, speeds and acceleration as the drive's
// counts) and the simulated drive's `sim.switches`, each mistake one error
// naming file, line and key.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt::cia402_homing_config_test {
namespace {

const std::string kRobot = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped_can.yaml";
constexpr std::size_t kDrive = 2;

// quadruped_can.yaml with `homing` on the drive's joint and `switches` in
// its bus's sim section.
std::string robot_with(const std::string& homing, const std::string& switches) {
  std::ifstream in(kRobot);
  std::stringstream text;
  text << in.rdbuf();
  std::string robot = text.str();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = robot.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) robot.replace(at, from.size(), to);
  };
  replace("node_id: 32, ", "node_id: 32, homing: " + homing + ", ");
  replace("      max_speed_dps: 600\n\n",
          "      max_speed_dps: 600\n      switches: " + switches + "\n\n");
  replace("file: ../gaits/walk.yaml",
          "file: " + std::string(ANIMRT_SOURCE_DIR) + "/configs/gaits/walk.yaml");
  const std::string path = ::testing::TempDir() + "/cia402_homing.yaml";
  std::ofstream(path) << robot;
  return path;
}

std::string error_of(const std::string& homing, const std::string& switches = "[]") {
  try {
    load_robot_config(robot_with(homing, switches));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(loaded)";
}

TEST(Cia402HomingConfig, SwitchMethodsTakeSpeedsInDegreesAsCounts) {
  const RobotConfig c = load_robot_config(robot_with(
      "{method: 23, speed_dps: 20, zero_speed_dps: 5, acceleration_dps2: 100, timeout_s: 12}",
      "[{id: 32, home_from_deg: 10, home_to_deg: 15, positive_limit_deg: 90}]"));
  const auto o = options_of<Cia402JointOptions>(c.buses[kDrive].actuators[0].options);
  const double per_deg = c.buses[kDrive].actuators[0].ticks_per_rad * 3.141592653589793 / 180.0;
  EXPECT_EQ(o.homing.method, 23);
  EXPECT_EQ(o.homing.switch_speed, static_cast<std::uint32_t>(std::lround(20 * per_deg)));
  EXPECT_EQ(o.homing.zero_speed, static_cast<std::uint32_t>(std::lround(5 * per_deg)));
  EXPECT_EQ(o.homing.acceleration, static_cast<std::uint32_t>(std::lround(100 * per_deg)));
  EXPECT_DOUBLE_EQ(o.homing.timeout_s, 12.0);
  ASSERT_EQ(c.buses[kDrive].sim.switches.size(), 1u);
  const SimDriveSwitches& s = c.buses[kDrive].sim.switches[0];
  EXPECT_EQ(s.device_id, 32);
  EXPECT_TRUE(s.has_home);
  EXPECT_DOUBLE_EQ(s.home_from_deg, 10.0);
  EXPECT_DOUBLE_EQ(s.home_to_deg, 15.0);
  EXPECT_DOUBLE_EQ(s.positive_limit_deg, 90.0);
  EXPECT_LT(s.negative_limit_deg, -1e300);  // not fitted
}

TEST(Cia402HomingConfig, MistakesNameFileLineAndKey) {
  EXPECT_NE(error_of("{method: 12}").find("cia402_homing.yaml:103:"), std::string::npos)
      << error_of("{method: 12}");
  EXPECT_NE(error_of("{method: 12}")
                .find("joints.rh_hip.actuator.homing.method: expected a "
                      "homing method of CiA 402: 17-30"),
            std::string::npos)
      << error_of("{method: 12}");
  EXPECT_NE(error_of("{method: 19}").find("homing.speed_dps: required key is missing"),
            std::string::npos)
      << error_of("{method: 19}");  // a search needs its speed
  EXPECT_NE(error_of("{method: 19, speed_dps: -3}")
                .find("homing.speed_dps: expected a number "
                      "above 0"),
            std::string::npos)
      << error_of("{method: 19, speed_dps: -3}");
  EXPECT_NE(error_of("{method: 37, speed_dps: 3}")
                .find("homing.speed_dps: method 37 homes where the drive rests"),
            std::string::npos)
      << error_of("{method: 37, speed_dps: 3}");
  EXPECT_NE(error_of("{method: 19, speed: 3}").find("speed"), std::string::npos);
  // Switches belong to a CiA 402 drive's bus.
  try {
    std::string robot =
        "name: t\nloop: {rate_hz: 100}\nbuses:\n  b:\n    protocol: dynamixel2\n"
        "    port: /dev/ttyUSB0\n    sim: {switches: [{id: 1}]}\n";
    const std::string path = ::testing::TempDir() + "/switches_on_servos.yaml";
    std::ofstream(path) << robot;
    load_robot_config(path);
    ADD_FAILURE() << "switches taken on a Dynamixel bus";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "switches_on_servos.yaml:7:21: buses.b.sim.switches: switches are simulated "
                  "on cia402 drives only"),
              std::string::npos)
        << e.what();
  }
  const std::string backwards =
      error_of("{method: 37}", "[{id: 32, home_from_deg: 10, home_to_deg: 5}]");
  EXPECT_NE(backwards.find("hip_drive.sim.switches[0].home_to_deg: expected more than "
                           "home_from_deg"),
            std::string::npos)
      << backwards;
}

// A switch entry for a drive the bus does not have simulates nothing: one
// error at its id, naming the bus and the drives it has.
TEST(Cia402HomingConfig, SwitchesOfADriveTheBusLacksAreRefused) {
  const std::string path =
      robot_with("{method: 37}", "[{id: 32, home_from_deg: 10}, {id: 33, home_from_deg: 10}]");
  std::ifstream in(path);
  int line = 0;
  for (std::string text; std::getline(in, text);) {
    ++line;
    if (text.find("switches:") != std::string::npos) break;
  }
  try {
    load_robot_config(path);
    ADD_FAILURE() << "switches of drive 33 taken";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cia402_homing.yaml:" + std::to_string(line) + ":"), std::string::npos)
        << what;
    EXPECT_NE(what.find("hip_drive.sim.switches[1].id: no device on bus hip_drive has id 33 "
                        "(its devices: 32)"),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace animrt::cia402_homing_config_test
