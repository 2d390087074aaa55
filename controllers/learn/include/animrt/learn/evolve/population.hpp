#pragma once
// What every search does with a population before it ranks it: map each new
// genome through the grammar, turn the phenotype into a gait (curves that are
// not free in the current freedom stage held at their seed mean), and walk
// the valid gaits through the evaluator in one batch. Used by the
// single-objective GE search and by the Pareto search.

#include <cstddef>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/learn/evolve/grammar.hpp"
#include "animrt/learn/evolve/mapper.hpp"
#include "animrt/learn/evolve/random.hpp"
#include "animrt/learn/evolve/run_config.hpp"

namespace animrt::evolve {

struct Individual {
  Genome genome;
  bool mapped = false;  // the genome mapped to a complete phenotype
  bool valid = false;   // ... and that phenotype is a usable gait
  std::string phenotype;
  GaitFile gait;                   // when valid
  GaitMeasures measures;           // of the last walk
  int stage = -1;                  // freedom stage it was walked under (-1: not yet)
  double fitness = kWorstFitness;  // the single-objective score (search.hpp)
};

struct WalkBatch {
  int evaluations = 0;   // walks simulated
  int reused = 0;        // gaits not walked again: the same phenotype was walked before
  double seconds = 0.0;  // wall time of those walks
};

// The first generation: ramped full/grow genomes, not yet mapped or walked.
std::vector<Individual> initial_population(const Grammar& grammar, const SearchSettings& s,
                                           Rng& rng);

// Appends children to `next` until it holds `size`: each pair of parents is
// picked by `pick` (an index into `parents`), crossed over at one point and
// mutated (int flip), as the run's settings say.
void breed(const std::vector<Individual>& parents, const std::function<std::size_t()>& pick,
           const SearchSettings& s, std::size_t size, std::vector<Individual>& next, Rng& rng);

class PopulationWalker {
 public:
  // Checks the run's freedom stages against the seed gait's curves and the
  // seed's froude timing; throws InputError on a mismatch.
  PopulationWalker(const RunConfig& config, const Grammar& grammar, const GaitFile& seed);

  // The freedom stage in effect at `generation` (0 without stages).
  int stage_at(int generation) const;

  // Maps and walks every individual not yet walked under `stage`; the others
  // keep their measures. A phenotype walked before under the same stage (in
  // this batch or an earlier one) is not walked again unless the run file
  // says so (search.remember_walks): a walk depends only on its gait, so
  // its measures are the same. Children often repeat a
  // parent (a mutation in codons the mapping never reads, a crossover of two
  // equal parents), more so as a population converges.
  WalkBatch walk(std::vector<Individual>& pop, int stage, Evaluator& evaluator);

  // Phenotypes remembered before the memory starts afresh.
  static constexpr std::size_t kRememberedWalks = 50000;

 private:
  const RunConfig& config_;
  const Grammar& grammar_;
  const GaitFile& seed_;
  std::vector<std::vector<std::string>> held_;            // per freedom stage
  std::unordered_map<std::string, GaitMeasures> walked_;  // phenotype -> measures, this stage
  int walked_stage_ = -1;
};

}  // namespace animrt::evolve
