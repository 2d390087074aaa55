#include "animrt/runtime/robot_model.hpp"

#include <stdexcept>

namespace animrt {

std::string describe_motion(const MotionConfig& motion) {
  if (motion.type != "layers") return motion.type + " " + motion.file;
  std::string text = "layers [";
  for (std::size_t i = 0; i < motion.layers.size(); ++i) {
    text += (i ? ", " : "") + describe_motion(motion.layers[i]);
  }
  return text + "]";
}

RobotModel make_robot_model(const RobotConfig& config, std::span<const BusConfig* const> buses) {
  RobotModel m;
  m.name = config.name;
  m.rate_hz = config.rate_hz;
  m.period = from_seconds(1.0 / config.rate_hz);
  m.dt = to_seconds(m.period);
  m.safety = config.safety;
  m.motion = describe_motion(config.motion);
  const std::size_t n = config.joints.size();
  for (const JointSpec& joint : config.joints) {
    m.joint_names.push_back(joint.name);
    m.limits.push_back(joint.limits);
    m.home.push_back(joint.home);
    const bool prismatic = joint.type == JointType::prismatic;
    m.prismatic.push_back(prismatic ? 1 : 0);
    m.following_error.push_back(prismatic ? config.safety.following_error_m
                                          : config.safety.following_error_rad);
  }
  m.slots.resize(n);
  std::vector<bool> bound(n, false);
  for (std::size_t b = 0; b < buses.size(); ++b) {
    BusModel bus;
    bus.name = buses[b]->name;
    bus.health = buses[b]->health_limits.value_or(config.safety.health);
    for (std::size_t d = 0; d < buses[b]->actuators.size(); ++d) {
      const ActuatorBinding& actuator = buses[b]->actuators[d];
      const int j = actuator.joint_index;
      if (j < 0 || static_cast<std::size_t>(j) >= n) {
        throw std::logic_error("actuator bound to an unknown joint index");
      }
      m.slots[static_cast<std::size_t>(j)] = JointSlot{b, d};
      bound[static_cast<std::size_t>(j)] = true;
      bus.joint.push_back(j);
      bus.device_id.push_back(actuator.device_id);
      bus.device_health.push_back(actuator.health_limits.value_or(bus.health));
    }
    m.buses.push_back(std::move(bus));
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (!bound[j]) throw std::logic_error("joint " + m.joint_names[j] + " has no actuator");
  }
  for (const ImuConfig& imu : config.imus)
    m.imus.push_back(ImuModel{imu.name, imu.stale_timeout_s, imu.rate_hz});
  return m;
}

}  // namespace animrt
