#pragma once
// A held pose: some joints at fixed targets, for a cue that strikes a pose.

#include <memory>
#include <utility>
#include <vector>

#include "animrt/controllers/motion_source.hpp"

namespace animrt {

// (robot joint index, target in rad, or m for a prismatic joint) pairs.
std::unique_ptr<MotionSource> make_pose_source(std::vector<std::pair<int, double>> pose);

}  // namespace animrt
