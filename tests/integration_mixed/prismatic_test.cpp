// Prismatic joints: a linear actuator on Modbus driven directly in metres by
// a show whose keys are metres, against the simulated drive in lockstep; and
// the robot-file errors that keep metres and degrees apart.

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string path =
      ::testing::TempDir() + "/" +
      std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

// A robot with one prismatic joint on a Modbus TCP linear actuator (the
// shipped 0..0.1 m map) and one revolute joint on Dynamixel; `joint_extra`
// and `actuator_extra` are spliced into the prismatic joint.
std::string robot(const std::string& show_path, const std::string& joint_extra = "",
                  const std::string& actuator_extra = "",
                  const std::string& limits =
                      "{min_m: 0.01, max_m: 0.09, velocity_mps: 0.1, acceleration_mps2: 1.0}") {
  return "name: slider\n"
         "loop: {rate_hz: 100}\n"
         "safety: {watchdog_timeout_s: 0.1, start_ramp_s: 0.5, stop_ramp_s: 0.5}\n"
         "buses:\n"
         "  neck: {protocol: dynamixel2, port: /dev/ttyUSB0, baud: 1000000, timeout_ms: 50}\n"
         "  drive:\n"
         "    protocol: modbus-tcp\n"
         "    port: 192.168.1.50:502\n"
         "    timeout_ms: 50\n"
         "    sim: {time_constant_s: 0.02, max_speed_dps: 30}\n"
         "joints:\n"
         "  neck_pan:\n"
         "    limits: {min_deg: -60, max_deg: 60, velocity_dps: 120, acceleration_dps2: 600}\n"
         "    actuator: {bus: neck, id: 1}\n"
         "  slide:\n"
         "    type: prismatic\n"
         "    limits: " +
         limits +
         "\n"
         "    home_m: 0.05\n" +
         joint_extra + "    actuator: {bus: drive, slave: 1, map: " + kConfigsDir +
         "/modbus/linear_actuator.yaml" + actuator_extra +
         "}\n"
         "motion: {type: show, file: " +
         show_path + "}\n";
}

const char* kShowInMetres =
    "name: push\n"
    "joints:\n"
    "  slide:\n"
    "    unit: m\n"
    "    interpolation: linear\n"
    "    keys: [[0, 0.05], [1.0, 0.08], [2.0, 0.08]]\n"
    "  neck_pan: {keys: [[0, 0], [1.0, 10]]}\n";

std::string error_of(const std::string& robot_text) {
  try {
    load_robot(write("robot.yaml", robot_text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Prismatic, AShowInMetresMovesALinearActuator) {
  LoadedRobot loaded = load_robot(write("robot.yaml", robot(write("show.yaml", kShowInMetres))));
  ASSERT_EQ(loaded.config.joints.size(), 2u);
  const JointSpec& slide = loaded.config.joints[1];
  EXPECT_EQ(slide.type, JointType::prismatic);
  EXPECT_DOUBLE_EQ(slide.limits.max_position, 0.09);
  EXPECT_DOUBLE_EQ(slide.limits.max_velocity, 0.1);
  EXPECT_DOUBLE_EQ(slide.home, 0.05);

  // The show's value at 1.5 s: 0.08 m on the slide, 10 deg on the neck.
  std::vector<double> targets(2, 0.0);
  loaded.motion->sample(1.5, targets);
  EXPECT_DOUBLE_EQ(targets[1], 0.08);
  EXPECT_NEAR(targets[0], deg_to_rad(10.0), 1e-12);

  SimulatedBackend simulated;
  FigureOptions lockstep;
  lockstep.lockstep = true;
  Figure figure(std::move(loaded), simulated, lockstep);
  RunOptions options = figure.run_options();
  options.raise_device_threads = nullptr;
  options.duration_s = 2.0;
  options.request_realtime = false;
  RunSummary s = figure.run(options);
  EXPECT_EQ(s.end_reason, EndReason::duration) << format_summary(s);
  EXPECT_TRUE(s.faults.empty());
  ASSERT_EQ(s.joints.size(), 2u);
  EXPECT_TRUE(s.joints[1].prismatic);
  EXPECT_FALSE(s.joints[0].prismatic);
  // The drive follows within its model's lag (20 ms at up to 0.1 m/s: 2 mm).
  EXPECT_LT(s.joints[1].max_tracking_error_rad, 0.003) << format_summary(s);
  EXPECT_GT(s.joints[1].max_tracking_error_rad, 0.0);
  // Back home in metres: the drive's own position (register value in m).
  EXPECT_NEAR(simulated.devices()[1]->device_position(1), 0.05, 1e-3);
  const std::string text = format_summary(s);
  EXPECT_NE(text.find("  slide          rms "), std::string::npos) << text;
  EXPECT_NE(text.find(" mm\n"), std::string::npos) << text;
}

TEST(Prismatic, RobotFileErrorsKeepMetresAndDegreesApart) {
  const std::string show = write("show.yaml", kShowInMetres);
  // Degrees on a prismatic joint.
  std::string e = error_of(
      robot(show, "", "", "{min_deg: 0, max_deg: 10, velocity_dps: 1, acceleration_dps2: 1}"));
  EXPECT_NE(e.find(":17:14: joints.slide.limits.min_deg: unknown key (expected one of: min_m, "
                   "max_m, velocity_mps, acceleration_mps2)"),
            std::string::npos)
      << e;
  // A stroke per radian on a joint that is already in metres.
  e = error_of(robot(show, "", ", m_per_rad: 0.1"));
  EXPECT_NE(e.find("joints.slide.actuator.m_per_rad: joint slide is prismatic"), std::string::npos)
      << e;
  // A prismatic joint on a bus of rotary servos.
  std::string on_dynamixel = robot(show);
  on_dynamixel.replace(on_dynamixel.find("{bus: drive, slave: 1, map: "),
                       on_dynamixel.find("}\nmotion") - on_dynamixel.find("{bus: drive, slave"),
                       "{bus: neck, id: 2");
  e = error_of(on_dynamixel);
  EXPECT_NE(e.find("joints.slide.actuator.bus: joint slide is prismatic, and bus neck "
                   "(dynamixel2) drives revolute joints only"),
            std::string::npos)
      << e;
  // Limits beyond the drive's stroke, named in metres.
  e = error_of(robot(show, "", ", zero_m: 0.02"));
  EXPECT_NE(e.find("joints.slide.limits.max_m: 0.09 m maps to 0.11 m, outside the range"),
            std::string::npos)
      << e;
  // A show in degrees for the prismatic joint.
  e = error_of(robot(write("deg.yaml", "joints:\n  slide: {unit: deg, keys: [[0, 0.05]]}\n")));
  EXPECT_NE(e.find("deg.yaml:2:17: joints.slide.unit: unit deg, but joint 'slide' is prismatic "
                   "(its limits are in metres); use unit: m"),
            std::string::npos)
      << e;
  // A key outside the stroke, in metres.
  e = error_of(robot(write("far.yaml", "joints:\n  slide: {keys: [[0, 0.05], [1, 0.5]]}\n")));
  EXPECT_NE(e.find("key at 1 s is 0.5 m, outside the joint's limits 0.01..0.09 m"),
            std::string::npos)
      << e;
  // A gait produces angles: it cannot drive a prismatic joint.
  const std::string gait =
      write("gait.yaml",
            "name: g\nstride_frequency_hz: 1\ncurves: {c: \"3 + sin(2*PI*t)\"}\n"
            "limbs: {a: 0.0}\njoints:\n  slide: {curve: c, limb: a}\n");
  std::string with_gait = robot(show);
  with_gait.replace(with_gait.find("motion: {type: show"), std::string::npos,
                    "motion: {type: gait, file: " + gait + "}\n");
  e = error_of(with_gait);
  EXPECT_NE(e.find("a gait drives angles, and joint slide is prismatic (metres); drive it with "
                   "a show"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace animrt
