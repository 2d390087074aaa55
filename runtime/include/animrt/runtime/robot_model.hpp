#pragma once
// The immutable half of a run (the cycle's model, as MuJoCo's mjModel is to
// mjData): joints and their limits, where each joint's actuator sits, the
// loop period, the safety settings and what every bus serves. Built once
// before the run; the cycle only reads it.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

// Where a joint's actuator lives: bus index and device index on that bus.
struct JointSlot {
  std::size_t bus = 0;
  std::size_t device = 0;
};

struct BusModel {
  std::string name;
  std::vector<int> joint;      // per device: the robot joint it drives
  std::vector<int> device_id;  // per device: its bus address
  HealthLimits health{};       // the bus's health_limits, else safety.health
  // Per device: its own health_limits (over the bus's), else `health`.
  std::vector<HealthLimits> device_health{};

  const HealthLimits& health_of(std::size_t device) const {
    return device < device_health.size() ? device_health[device] : health;
  }
};

struct ImuModel {
  std::string name;
  double stale_timeout_s = 0.25;
  double rate_hz = 100.0;  // its report rate
};

struct RobotModel {
  std::string name;
  double rate_hz = 0.0;
  Nanos period = 0;
  double dt = 0.0;  // period in seconds
  SafetyConfig safety;
  std::string motion;  // what plays, for messages: "gait configs/gaits/walk.yaml"

  std::vector<std::string> joint_names;
  std::vector<JointLimits> limits;
  std::vector<double> home;
  std::vector<std::uint8_t> prismatic;
  std::vector<double> following_error;  // per joint: the watch's threshold (rad or m)
  std::vector<JointSlot> slots;         // per joint
  std::vector<BusModel> buses;
  std::vector<ImuModel> imus;  // the first is the trunk's

  std::size_t joint_count() const { return joint_names.size(); }
};

// "gait FILE", or for layers "layers [gait FILE, show FILE]".
std::string describe_motion(const MotionConfig& motion);

// Throws std::logic_error when an actuator names an unknown joint or a joint
// has no actuator (the config loader rejects both earlier, with a location).
RobotModel make_robot_model(const RobotConfig& config, std::span<const BusConfig* const> buses);

}  // namespace animrt
