#pragma once
// `animrt serve ROBOT --cues CUES.yaml`: a figure in service. It ramps up,
// plays the cue file's idle cue and the cues its triggers ask for (OSC over
// UDP, Art-Net, sACN), crossfading between them, until a stop (docs/show_control.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_serve_command(CLI::App& app);

}  // namespace animrt::cli
