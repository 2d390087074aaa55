#pragma once
// `animrt view TELEMETRY.csv [--robot ROBOT]`: a recorded run replayed
// through the dashboard's API, with a time slider (docs/dashboard.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_view_command(CLI::App& app);

}  // namespace animrt::cli
