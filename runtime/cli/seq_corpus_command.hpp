#pragma once
// `animrt seq corpus`: a generated corpus of skinned mesh sequences walked
// on MuJoCo (docs/seqnet.md, "Generated corpus").

#include <CLI/CLI.hpp>

namespace animrt::cli {

// Adds `corpus` to the `seq` subcommand group.
void add_seq_corpus_command(CLI::App& seq);

}  // namespace animrt::cli
