#pragma once
// `animrt sim ROBOT`: serves a robot's simulated devices for another program
// until a stop signal, with an optional control socket (docs/cli.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_sim_command(CLI::App& app);

}  // namespace animrt::cli
