#pragma once
// `train` of the sequence network (docs/seqnet.md), added to
// animrt-seqnet's command line.

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_seq_net_commands(CLI::App& app);

}  // namespace animrt::cli
