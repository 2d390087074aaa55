#pragma once
// `animrt gait calibrate ROBOT --physics MODEL.xml`: walks the robot's
// steerable gait on a MuJoCo model over a grid of speeds and turn rates and
// writes what it achieved (docs/gait.md, "Calibration").

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_gait_command(CLI::App& app);
// `animrt gait measure` (gait_measure_command.cpp), added under `gait`.
void add_gait_measure_command(CLI::App& gait);

}  // namespace animrt::cli
