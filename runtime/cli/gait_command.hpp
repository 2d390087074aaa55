#pragma once
// `animrt gait calibrate ROBOT --physics MODEL.xml`: walks the robot's
// steerable gait on a MuJoCo model over a grid of speeds and turn rates and
// writes what it achieved (docs/gait.md, "Calibration").

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_gait_command(CLI::App& app);

}  // namespace animrt::cli
