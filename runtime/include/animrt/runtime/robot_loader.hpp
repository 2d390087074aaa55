#pragma once
// Everything a run needs from files, loaded and validated in one place, so
// `animrt validate` checks exactly what `animrt run` would use.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/gait/balanced_gait_source.hpp"
#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

struct LoadedRobot {
  RobotConfig config;
  std::unique_ptr<MotionSource> motion;
  // A gait motion with a `steering` section: its command range.
  std::optional<GaitSteering> steering;
  // What a run would likely fault on though every file is valid (a motion
  // faster than its servos turn, a bus whose answers come back too late):
  // one line each, with the numbers.
  std::vector<std::string> warnings;
  // The motion when it is a gait with `balance:` (null otherwise): it plays
  // its reflex once given the figure's legs (BalancedGaitSource::attach),
  // which the caller builds from the robot's model.
  BalancedGaitSource* balanced = nullptr;
};

// Loads the robot file and its motion source. Throws InputError on the first
// problem in any of the files.
LoadedRobot load_robot(const std::string& path);

// One motion for the robot (a show, a gait or layers, as its motion section
// names them), built and checked against its joints as load_robot does.
// Throws InputError.
std::unique_ptr<MotionSource> load_motion_source(const MotionConfig& motion,
                                                 const RobotConfig& config);
// The same, keeping what the motion is warned of (a learned model never
// measured better than interpolation) in `warnings`, one line each.
std::unique_ptr<MotionSource> load_motion_source(const MotionConfig& motion,
                                                 const RobotConfig& config,
                                                 std::vector<std::string>& warnings);

// One line per bus whose actuators nothing stops if animrt dies (kill -9, a
// crash, a power cut), or whose guard must be set outside animrt:
// "bus NAME (PROTOCOL): what to know".
std::vector<std::string> device_guard_notes(const RobotConfig& config);

}  // namespace animrt
