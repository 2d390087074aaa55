// animrt-tools' side of the tools (see tools_exec.hpp): the commands themselves.

#include "evolve_command.hpp"
#include "gait_command.hpp"
#include "head_command.hpp"
#include "herd_command.hpp"
#include "seq_command.hpp"
#include "seq_corpus_command.hpp"
#include "tools_exec.hpp"

namespace animrt::cli {

void add_tool_commands(CLI::App& app) {
  add_evolve_command(app);
  add_gait_command(app);
  add_head_command(app);
  add_herd_command(app);
  auto* seq = app.add_subcommand(
      "seq", "Mesh sequences: generated corpus, deformation features, the sequence network");
  seq->require_subcommand(1);
  add_seq_corpus_command(*seq);
  add_seq_command(*seq);
}

}  // namespace animrt::cli
