#pragma once
// `animrt record ROBOT --out SHOW.yaml`: puppeteering. Torque off, the
// figure moved by hand, its positions recorded at the loop rate and reduced
// to keys within a bound; the show plays back through `animrt run`.

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_record_command(CLI::App& app);

}  // namespace animrt::cli
