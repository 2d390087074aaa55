#pragma once
// The GE search: ramped full/grow initial population, then per generation
// elites (copied unchanged), tournament selection, fixed-point crossover and
// int-flip mutation, generational replacement. Invalid individuals (mapping
// ran out of wraps, or the phenotype is not a usable gait) score
// kWorstFitness and are counted. Everything random comes from one Rng
// seeded by the run file, and evaluation results do not depend on how they
// were computed, so a seed always gives the same run.

#include <functional>
#include <string>
#include <vector>

#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/mapper.hpp"
#include "animrt/learn/evolve/population.hpp"
#include "animrt/learn/evolve/run_config.hpp"

namespace animrt::evolve {

struct GenerationStats {
  int generation = 0;
  double best = 0.0;     // lowest fitness
  double average = 0.0;  // over the whole population, invalid and fallen included
  double stddev = 0.0;
  int invalid = 0;       // individuals that did not map to a usable gait
  int fell = 0;          // valid individuals whose walk fell
  int evaluations = 0;   // walks simulated this generation
  int reused = 0;        // gaits whose phenotype was walked before (population.hpp)
  double seconds = 0.0;  // wall time of this generation's evaluations
  std::string best_phenotype;
  GaitMeasures best_measures;
};

struct SearchResult {
  std::vector<GenerationStats> history;
  Individual best;  // best of the last generation
  long evaluations = 0;
  long reused = 0;
  long invalid = 0;
  bool stopped = false;  // SearchHooks::stop ended the run before its last generation
};

// What a run tells its caller and asks it, between generations, on the
// search's thread (never while a generation is being evaluated).
struct SearchHooks {
  // After each generation: its statistics (as in SearchResult::history) and
  // its best individual.
  std::function<void(const GenerationStats&, const Individual& best)> generation;
  // Asked after each generation but the last: true ends the run there, that
  // generation's best being the result (SearchResult::stopped). Under MPI
  // every rank must give the same answer.
  std::function<bool()> stop;
};

class Search {
 public:
  // Checks the seed gait against the grammar's run file (freedom names,
  // froude timing) and throws InputError on a mismatch.
  Search(RunConfig config, Grammar grammar, GaitFile seed, ModelInfo model, Evaluator& evaluator);

  SearchResult run(const std::function<void(const GenerationStats&)>& progress = {});
  SearchResult run(const SearchHooks& hooks);

 private:
  void evaluate(std::vector<Individual>& pop, int generation, GenerationStats& stats);

  RunConfig config_;
  Grammar grammar_;
  GaitFile seed_;
  ModelInfo model_;
  Evaluator& evaluator_;
  GaitTargets targets_;
  PopulationWalker walker_;
};

}  // namespace animrt::evolve
