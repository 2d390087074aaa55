#pragma once
// `animrt seq features SEQ --out F.bin [--clip NAME]` and
// `animrt seq reconstruct F.bin --out DIR`: mesh sequences to deformation
// features and back (docs/seqnet.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

// Adds `features` and `reconstruct` to the `seq` subcommand group.
void add_seq_command(CLI::App& seq);

}  // namespace animrt::cli
