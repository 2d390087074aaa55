#pragma once
// Loading a gait file and binding it to a robot's joints as a MotionSource.

#include <memory>
#include <span>
#include <string>

#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

// Loads and validates a gait file and binds its joint mappings to `joints`
// (by name). Throws InputError naming the file, line, column and key for any
// problem, including a mapping to a joint the robot does not have.
std::unique_ptr<MotionSource> load_gait_source(const std::string& gait_path,
                                               std::span<const JointSpec> joints);

}  // namespace animrt
