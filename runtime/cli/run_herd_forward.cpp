// animrt hands a run steered by a herd over to animrt-tools (see run_herd.hpp).

#include <cstdlib>

#include "run_herd.hpp"
#include "tools_exec.hpp"

namespace animrt::cli {

void run_herd_here(const std::string& scene) {
  if (scene.empty()) return;
  std::exit(exec_tools(remembered_argv(), "run --herd"));
}

std::unique_ptr<RunHerd> join_run_herd(const std::string&, const std::string&, const Figure&,
                                       const SimulatedBackend&, RunControls&) {
  return nullptr;  // run_herd_here handed every herd's run over
}

}  // namespace animrt::cli
