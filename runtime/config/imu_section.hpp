#pragma once
// The robot file's `imus:` list and the tilt watch's safety keys.

#include <vector>

#include "animrt/bridge/imu/imu_config.hpp"
#include "animrt/core/yaml_doc.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

// Throws InputError (file, line, column, key) on the first problem.
std::vector<ImuConfig> parse_imus(const YamlNode& list, double rate_hz);

// safety.tilt_limit_deg, tilt_time_s, on_tilt (hold | torque_off),
// tilt_hold_s, into `safety`.
void parse_tilt_watch(const YamlNode& safety_node, SafetyConfig& safety);

}  // namespace animrt
