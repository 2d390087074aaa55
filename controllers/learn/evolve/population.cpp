// Mapping and walking a population (see population.hpp).

#include "animrt/learn/evolve/population.hpp"

#include <algorithm>
#include <chrono>
#include <string_view>

#include "animrt/core/error.hpp"
#include "animrt/learn/evolve/operators.hpp"
#include "animrt/learn/evolve/phenotype.hpp"

namespace animrt::evolve {

std::vector<Individual> initial_population(const Grammar& grammar, const SearchSettings& s,
                                           Rng& rng) {
  std::vector<Individual> pop;
  auto genomes = s.mapping == Mapping::structured
                     ? ramped_structured(grammar, s.population, s.init, rng)
                     : ramped_full_grow(grammar, s.population, s.init, rng);
  for (auto& g : genomes) {
    Individual ind;
    ind.genome = std::move(g);
    pop.push_back(std::move(ind));
  }
  return pop;
}

void breed(const std::vector<Individual>& parents, const std::function<std::size_t()>& pick,
           const SearchSettings& s, std::size_t size, std::vector<Individual>& next, Rng& rng) {
  while (next.size() < size) {
    Genome a = parents[pick()].genome;
    Genome b = parents[pick()].genome;
    fixed_point_crossover(a, b, s.crossover, rng);
    int_flip_mutation(a, s.mutation, s.init.codon_size, rng);
    int_flip_mutation(b, s.mutation, s.init.codon_size, rng);
    for (Genome* g : {&a, &b}) {
      if (next.size() >= size) break;
      Individual child;
      child.genome = std::move(*g);
      next.push_back(std::move(child));
    }
  }
}

PopulationWalker::PopulationWalker(const RunConfig& config, const Grammar& grammar,
                                   const GaitFile& seed)
    : config_(config), grammar_(grammar), seed_(seed) {
  if (!seed_.froude) {
    throw InputError({seed_.file, 0, 0}, "froude",
                     "the seed gait of an evolve run needs froude timing (the fitness targets "
                     "come from the Froude number)");
  }
  if (config_.search.mapping == Mapping::structured) {
    const Rule& start = grammar_.start();
    if (start.productions.size() != 1) {
      throw InputError(config_.search.mapping_where, "search.mapping",
                       "structured mapping needs a start rule with a single production (one "
                       "codon segment per curve in it); <" +
                           start.name + "> in " + grammar_.file() + " has " +
                           std::to_string(start.productions.size()) + " productions");
    }
    if (structured_segments(grammar_) == 0) {
      throw InputError(config_.search.mapping_where, "search.mapping",
                       "structured mapping found nothing to map: no non-terminal of <" +
                           start.name + ">'s production in " + grammar_.file() +
                           " makes a choice, so there are no codon segments");
    }
  }
  const auto means = curve_means(seed_);
  for (const auto& stage : config_.freedom) {
    std::vector<std::string> held = means;
    for (const auto& name : stage.free) {
      const auto it = std::find_if(seed_.curves.begin(), seed_.curves.end(),
                                   [&](const GaitCurve& c) { return c.name == name; });
      if (it == seed_.curves.end()) {
        throw InputError(stage.where, "fitness.freedom.free",
                         "no curve '" + elide(name) + "' in the seed gait " + seed_.file);
      }
      held[static_cast<std::size_t>(it - seed_.curves.begin())].clear();
    }
    held_.push_back(std::move(held));
  }
}

int PopulationWalker::stage_at(int generation) const {
  int stage = 0;
  for (std::size_t i = 0; i < config_.freedom.size(); ++i) {
    if (config_.freedom[i].from_generation <= generation) stage = static_cast<int>(i);
  }
  return stage;
}

WalkBatch PopulationWalker::walk(std::vector<Individual>& pop, int stage, Evaluator& evaluator) {
  static const std::vector<std::string> kNoneHeld;
  const auto& held = held_.empty() ? kNoneHeld : held_[static_cast<std::size_t>(stage)];
  // Stages only move forward: the walks of earlier ones are not needed again.
  if (stage != walked_stage_) walked_.clear();
  walked_stage_ = stage;
  if (walked_.size() > kRememberedWalks || !config_.search.remember_walks) walked_.clear();
  const MapLimits limits{config_.search.max_wraps};
  WalkBatch batch;
  std::vector<std::size_t> todo;     // the first individual of each phenotype to walk
  std::vector<std::size_t> repeats;  // later individuals with one of those phenotypes
  std::unordered_map<std::string_view, std::size_t> first_of;
  for (std::size_t i = 0; i < pop.size(); ++i) {
    Individual& ind = pop[i];
    if (ind.stage == stage) continue;  // already walked under these rules
    if (ind.stage < 0) {
      const MapResult m = config_.search.mapping == Mapping::structured
                              ? map_structured(grammar_, ind.genome, limits)
                              : map_genome(grammar_, ind.genome, limits);
      ind.mapped = m.valid;
      ind.phenotype = m.phenotype;
    }
    ind.valid = ind.mapped;
    ind.stage = stage;
    ind.measures = GaitMeasures{};
    if (!ind.valid) continue;
    PhenotypeGait pg = make_phenotype_gait(seed_, ind.phenotype, held);
    ind.valid = pg.valid;
    if (!pg.valid) continue;
    ind.gait = std::move(pg.gait);
    ind.gait.name = config_.name;
    if (const auto it = walked_.find(ind.phenotype); it != walked_.end()) {
      ind.measures = it->second;
      ++batch.reused;
    } else if (config_.search.remember_walks && first_of.contains(ind.phenotype)) {
      repeats.push_back(i);
      ++batch.reused;
    } else {
      first_of.emplace(ind.phenotype, i);
      todo.push_back(i);
    }
  }
  std::vector<const GaitFile*> gaits;
  for (auto i : todo) gaits.push_back(&pop[i].gait);
  std::vector<GaitMeasures> measures(gaits.size());
  const auto t0 = std::chrono::steady_clock::now();
  evaluator.walk_all(gaits, config_.walk, measures);
  batch.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  batch.evaluations = static_cast<int>(todo.size());
  for (std::size_t k = 0; k < todo.size(); ++k) {
    pop[todo[k]].measures = measures[k];
    if (config_.search.remember_walks) walked_.emplace(pop[todo[k]].phenotype, measures[k]);
  }
  for (auto i : repeats) pop[i].measures = pop[first_of.at(pop[i].phenotype)].measures;
  return batch;
}

}  // namespace animrt::evolve
