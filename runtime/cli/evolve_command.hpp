#pragma once
// `animrt evolve RUN.yaml --out GAIT.yaml`: Grammatical Evolution of a gait
// against a MuJoCo model (docs/evolve.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_evolve_command(CLI::App& app);

}  // namespace animrt::cli
