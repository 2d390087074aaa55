#pragma once
// `animrt seq train` runs animrt-seqnet, the executable beside animrt that
// holds the libtorch part, with the same arguments (docs/seqnet.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_seq_net_forwarders(CLI::App& seq);

}  // namespace animrt::cli
