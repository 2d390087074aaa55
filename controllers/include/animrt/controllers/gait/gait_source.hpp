#pragma once
// Loading a gait file and binding it to a robot's joints as a MotionSource.

#include <memory>
#include <span>
#include <string>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/motion_source.hpp"
#include "animrt/core/joint.hpp"

namespace animrt {

// Loads and validates a gait file and binds its joint mappings to `joints`
// (by name). Throws InputError naming the file, line, column and key for any
// problem, including a mapping to a joint the robot does not have.
//
// Target of joint j at time t (seconds), f the stride frequency:
//   deg_to_rad(sign * scale * curve(f * t - phase_of_limb) + offset_deg)
std::unique_ptr<MotionSource> load_gait_source(const std::string& gait_path,
                                               std::span<const JointSpec> joints);

// The same for a gait already in memory (e.g. one the evolver built). Runs
// validate_gait() first; errors are reported at the gait's locations.
std::unique_ptr<MotionSource> make_gait_source(const GaitFile& gait,
                                               std::span<const JointSpec> joints);

}  // namespace animrt
