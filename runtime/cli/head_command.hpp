#pragma once
// `animrt head features|corpus|train|synth|eval|table`: speech-driven head
// motion from the command line (docs/head.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_head_command(CLI::App& app);

}  // namespace animrt::cli
