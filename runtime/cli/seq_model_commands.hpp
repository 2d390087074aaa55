#pragma once
// `animrt seq generate` and `animrt seq complete`: a trained sequence model
// run by the plain C++ inference (no libtorch), on OBJ frames for a mesh
// model and on joint-angle CSVs for a joint model (docs/seqnet.md).

#include <CLI/CLI.hpp>

namespace animrt::cli {

// Adds `generate` and `complete` to the `seq` subcommand group.
void add_seq_model_commands(CLI::App& seq);

}  // namespace animrt::cli
