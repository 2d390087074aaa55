#pragma once
// A MuJoCo walk played as a robot file's figure plays it on the runtime:
// its joint limits at its loop rate, and the balance reflex reading the
// attitude as its trunk IMU reports it. Shared by `gait measure --robot`
// and `evolve --robot`, so a measure and the fitness walk the same way.

#include <string>

#include "animrt/controllers/gait/gait_simulator.hpp"

namespace animrt::cli {

// Fills `settings`' joint limits (one per model joint, by name; a model
// joint the robot lacks is an error naming the file) and loop period; with
// an IMU in `imus:`, the reflex reads the attitude once every report period
// and as old as the part's (its `sim:` latency, else one report period).
void walk_as_robot(const std::string& robot_file, const evolve::ModelInfo& model,
                   evolve::WalkSettings& settings);

// One line saying how `settings` plays the walk (for a command's header).
std::string describe_walk_as_robot(const std::string& robot_file,
                                   const evolve::WalkSettings& settings);

}  // namespace animrt::cli
