#pragma once
// `animrt servo PORT --protocol P --id N ACTION`: sets up one serial servo
// (id, baud, return delay, mode, limits, reboot, factory reset), each change
// read back (docs/cli.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_servo_command(CLI::App& app);

}  // namespace animrt::cli
