#pragma once
// `animrt seq features SEQ --out F.bin [--clip NAME]` and
// `animrt seq reconstruct F.bin --out DIR`: mesh sequences to deformation
// features and back (docs/seqnet.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

void add_seq_command(CLI::App& app);

}  // namespace animrt::cli
