#pragma once
// `animrt calibrate ROBOT`: each joint moved by hand through its range and
// to its home pose, torque off; zero_ticks, direction and the limits written
// back into the robot file in place (docs/cli.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_calibrate_command(CLI::App& app);

}  // namespace animrt::cli
