#pragma once
// The offline tools (learners, generators, the herd) live in a second
// executable, animrt-tools, beside animrt: a figure's runtime package carries
// no learner. animrt hands a tool's command line to it unchanged, git-style.

#include <CLI/CLI.hpp>

namespace animrt::cli {

// The command lines animrt-tools answers that animrt does not: registered by
// animrt as forwarders (so its --help lists them), by animrt-tools as the
// commands themselves.
void add_tool_commands(CLI::App& app);

// Replaces this process by animrt-tools with the same arguments. Returns
// only when animrt-tools is not installed, with the exit code after one line
// that says so, naming `command_name` ("run --herd"; default: argv[1]).
int exec_tools(char** argv, const std::string& command_name = "");

// argv as main() got it, for exec_tools from a command's callback.
void remember_argv(char** argv);
char** remembered_argv();

}  // namespace animrt::cli
