#include "animrt/runtime/robot_loader.hpp"

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/show/show_file.hpp"

namespace animrt {

namespace {

std::unique_ptr<MotionSource> make_source(const MotionConfig& motion, const std::vector<JointSpec>& joints) {
  if (motion.type == "layers") {
    std::vector<std::unique_ptr<MotionSource>> layers;
    for (const MotionConfig& layer : motion.layers) layers.push_back(make_source(layer, joints));
    return make_layered_source(std::move(layers));
  }
  if (motion.type == "show") return load_show_source(motion.file, joints);
  if (motion.type == "gait") {
    return load_gait_source(motion.file, joints);
  } else if (motion.type == "head") {
    return head::make_head_source(*motion.head, joints);
  } else {
    throw InputError(motion.where, "motion.type",
                     "unsupported motion type \"" + motion.type + "\"");
  }
}

}  // namespace

LoadedRobot load_robot(const std::string& path) {
  LoadedRobot robot;
  robot.config = load_robot_config(path);
  robot.motion = make_source(robot.config.motion, robot.config.joints);
  return robot;
}

}  // namespace animrt
