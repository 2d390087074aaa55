#pragma once
// `run --herd`: the robot walks as one agent of a herd, whose crowds run on
// Recast. The herd is one of the offline tools (tools_exec.hpp): animrt-tools
// steers the run itself, animrt hands such a run over to animrt-tools before
// anything moves.

#include <memory>
#include <string>

#include "animrt/core/clock.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/run_controls.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace animrt::cli {

class RunHerd {
 public:
  virtual ~RunHerd() = default;
  virtual void start(Nanos t0) = 0;
  virtual void stop() = 0;
  virtual std::string report() const = 0;
};

// Called first thing in `run` with --herd's scene: returns when this
// executable steers herds itself, else execs animrt-tools (or, when it is not
// installed, exits after one line that says so).
void run_herd_here(const std::string& scene);

// The herd that steers the figure as `agent` of `scene`, seeing the walk the
// physics measures when there is physics; null without a scene.
std::unique_ptr<RunHerd> join_run_herd(const std::string& scene, const std::string& agent,
                                       const Figure& figure, const SimulatedBackend& simulated,
                                       RunControls& controls);

}  // namespace animrt::cli
