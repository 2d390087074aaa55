#pragma once
// The Pareto mode of `animrt evolve` (docs/evolve.md, "Pareto front").

#include <string>

#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/run_config.hpp"

namespace animrt::cli {

struct ParetoOutput {
  std::string dir;   // gait_NN.yaml, front.csv, front.svg, history.csv
  bool lead = true;  // MPI rank 0 (or no MPI): prints and writes
  bool quiet = false;
};

int run_pareto_search(const evolve::RunConfig& config, evolve::Grammar grammar,
                      const GaitFile& seed, const evolve::ModelInfo& info,
                      evolve::Evaluator& evaluator, const ParetoOutput& output);

}  // namespace animrt::cli
