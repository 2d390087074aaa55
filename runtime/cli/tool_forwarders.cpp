// animrt's side of the tools (see tools_exec.hpp): each tool's command is a
// forwarder that hands the whole command line, --help included, to
// animrt-tools.

#include <utility>

#include "subcommand.hpp"
#include "tools_exec.hpp"

namespace animrt::cli {

void add_tool_commands(CLI::App& app) {
  // The descriptions the tools' own commands give.
  const std::pair<const char*, const char*> tools[] = {
      {"evolve", "Evolve a gait with Grammatical Evolution against a MuJoCo model"},
      {"gait", "Steerable gaits"},
      {"head", "Speech-driven head motion: features, corpus, train, synth, eval"},
      {"herd", "Run a herd of walking figures offline (flocks, crowds)"},
      {"seq", "Mesh sequences: generated corpus, deformation features, the sequence network"},
  };
  for (const auto& [name, description] : tools) {
    auto* cmd = app.add_subcommand(name, std::string(description) + " (animrt-tools)");
    cmd->prefix_command();
    cmd->set_help_flag();
    cmd->callback([] {
      const int code = exec_tools(remembered_argv());
      throw CLI::RuntimeError(code);
    });
  }
}

}  // namespace animrt::cli
