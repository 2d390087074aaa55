#pragma once
// The multi-objective search (NSGA-II over GE genomes): instead of one
// weighted score, three objectives are minimised together and the search
// returns the front of gaits none of which is beaten in all three:
//
//   speed error   |v - v*| / v*, against the seed's Froude speed
//   energy        E / (m g L*), the cost of transport per stride
//   tilt          the torso's largest tilt from upright while walking, in
//                 degrees (a walk falls at 60: the stability margin is the
//                 rest)
//
// Each generation breeds N offspring from the population by binary
// tournaments on (front, crowding distance), with the GE crossover and
// mutation, walks them, and keeps the best N of parents and offspring by
// front and then by crowding distance. Fallen and invalid individuals rank
// behind every walker. Deterministic for a seed, however the walks are
// spread over threads or MPI ranks.

#include <functional>
#include <vector>

#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/pareto.hpp"
#include "animrt/learn/evolve/population.hpp"
#include "animrt/learn/evolve/run_config.hpp"

namespace animrt::evolve {

inline constexpr int kParetoObjectives = 3;

// The objectives of a walk (fallen or invalid: all +infinity).
Objectives pareto_objectives(const Individual& ind, const GaitTargets& targets, double mass_kg);

struct ParetoGeneration {
  int generation = 0;
  int front_size = 0;  // walkers on the first front
  int invalid = 0;
  int fell = 0;
  int evaluations = 0;
  double seconds = 0.0;
  // The least value of each objective among the first front's walkers.
  double best_speed_error = 0.0, best_energy = 0.0, best_tilt_deg = 0.0;
};

struct ParetoMember {
  Individual individual;
  Objectives objectives;
};

struct ParetoResult {
  std::vector<ParetoGeneration> history;
  // Walkers of the last generation's first front, one per phenotype, by
  // speed error.
  std::vector<ParetoMember> front;
  long evaluations = 0;
};

class ParetoSearch {
 public:
  ParetoSearch(RunConfig config, Grammar grammar, GaitFile seed, ModelInfo model,
               Evaluator& evaluator);
  ParetoResult run(const std::function<void(const ParetoGeneration&)>& progress = {});

 private:
  RunConfig config_;
  Grammar grammar_;
  GaitFile seed_;
  ModelInfo model_;
  Evaluator& evaluator_;
  GaitTargets targets_;
  PopulationWalker walker_;
};

}  // namespace animrt::evolve
