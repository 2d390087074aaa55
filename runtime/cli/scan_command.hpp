#pragma once
// `animrt scan PORT`: finds the devices on a serial port with safe queries
// only, prints them as a table and optionally drafts a robot file
// (docs/cli.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_scan_command(CLI::App& app);

}  // namespace animrt::cli
