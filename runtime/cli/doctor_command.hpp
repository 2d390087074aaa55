#pragma once
// `animrt doctor`: checks the host the way a figure needs it (serial
// adapters, latency timers, port permissions, real-time limits, kernel, CPU
// governor, CAN interfaces), each line OK, WARN or FAIL with its fix.

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_doctor_command(CLI::App& app);

}  // namespace animrt::cli
