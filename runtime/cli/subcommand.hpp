#pragma once
// How every subcommand other than run, validate and sim reports its result:
// the body's exit code, an InputError as exit 2 (one line naming file, line
// and key), any other error as exit 1. main() dispatches only its own
// subcommands, so the outcome leaves CLI11's parse as an exception.

#include <CLI/CLI.hpp>
#include <functional>

namespace animrt::cli {

// Exit codes (documented in the README).
inline constexpr int kExitOk = 0;
inline constexpr int kExitUsage = 1;
inline constexpr int kExitInvalidInput = 2;
inline constexpr int kExitDeviceError = 3;
// 4 (a fault ended the run) and 5 (torque cut) come from RunSummary::exit_code().
// The figure's run was clean, but its record is not: telemetry records or
// the summary JSON could not be written (RunSummary::exit_code() too).
inline constexpr int kExitRecordLost = 6;

void set_subcommand_body(CLI::App* cmd, std::function<int()> body);

// --help shows every option's default (option_defaults()->always_capture_default()),
// except an empty list's "[]" and a required option's placeholder (servo's
// "--id INT=-1 REQUIRED"), which say nothing: called once every command is
// added.
void hide_empty_defaults(CLI::App& app);

}  // namespace animrt::cli
