#include "animrt/runtime/robot_loader.hpp"

#include "animrt/controllers/gait/gait_source.hpp"

namespace animrt {

LoadedRobot load_robot(const std::string& path) {
  LoadedRobot robot;
  robot.config = load_robot_config(path);
  const MotionConfig& motion = robot.config.motion;
  if (motion.type == "gait") {
    robot.motion = load_gait_source(motion.file, robot.config.joints);
  } else {
    throw InputError(motion.where, "motion.type",
                     "unsupported motion type \"" + motion.type + "\"");
  }
  return robot;
}

}  // namespace animrt
