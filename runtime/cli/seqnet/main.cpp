// animrt-seqnet: the sequence network's training, the part
// of animrt that needs libtorch. Run through `animrt seq train`,
// which hands its arguments over unchanged, or on its own.

#include <CLI/CLI.hpp>

#include "../subcommand.hpp"
#include "animrt/learn/seqnet/blas_kernels.hpp"
#include "animrt/learn/seqnet/memory.hpp"
#include "seq_net_commands.hpp"

int main(int argc, char** argv) {
  // Before anything else: the BLAS kernels are fixed when it loads.
  animrt::seqnet::restart_with_better_blas_kernels(argv);
  animrt::seqnet::keep_freed_memory();
  CLI::App app{"animrt-seqnet: train the sequence network"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "animrt-seqnet " ANIMRT_VERSION);
  app.option_defaults()->always_capture_default();  // every --help shows the defaults
  animrt::cli::add_seq_net_commands(app);
  animrt::cli::hide_empty_defaults(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's own result (subcommand.hpp)
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == static_cast<int>(CLI::ExitCodes::Success) ? 0 : 1;
  }
  return 1;
}
