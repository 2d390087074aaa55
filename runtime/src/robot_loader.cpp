#include "animrt/runtime/robot_loader.hpp"

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/controllers/show/show_file.hpp"

namespace animrt {

namespace {

std::unique_ptr<MotionSource> make_source(const MotionConfig& motion,
                                          const std::vector<JointSpec>& joints) {
  if (motion.type == "layers") {
    std::vector<std::unique_ptr<MotionSource>> layers;
    for (const MotionConfig& layer : motion.layers) layers.push_back(make_source(layer, joints));
    return make_layered_source(std::move(layers));
  }
  if (motion.type == "show") return load_show_source(motion.file, joints);
  if (motion.type == "gait" || motion.type == "head") {
    auto source = motion.type == "gait" ? load_gait_source(motion.file, joints)
                                        : head::make_head_source(*motion.head, joints);
    // Gaits and head motion produce angles; only a show states metres.
    for (int j : source->driven_joints()) {
      const JointSpec& joint = joints[static_cast<std::size_t>(j)];
      if (joint.type == JointType::prismatic) {
        throw InputError(motion.where, "motion.type",
                         "a " + motion.type + " drives angles, and joint " + joint.name +
                             " is prismatic (metres); drive it with a show");
      }
    }
    return source;
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
