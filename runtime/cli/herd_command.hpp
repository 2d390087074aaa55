#pragma once
// `animrt herd SCENE.yaml`: a herd of walking figures run offline, faster
// than real time (docs/herd.md).

#include <CLI/CLI.hpp>
#include <string>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::cli {

void add_herd_command(CLI::App& app);

}  // namespace animrt::cli
