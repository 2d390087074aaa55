// The generational GE loop (see search.hpp).

#include "animrt/controllers/evolve/search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "animrt/controllers/evolve/phenotype.hpp"

namespace animrt::evolve {

Search::Search(RunConfig config, Grammar grammar, GaitFile seed, ModelInfo model,
               Evaluator& evaluator)
    : config_(std::move(config)),
      grammar_(std::move(grammar)),
      seed_(std::move(seed)),
      model_(std::move(model)),
      evaluator_(evaluator) {
  if (!seed_.froude) {
    throw InputError({seed_.file, 0, 0}, "froude",
                     "the seed gait of an evolve run needs froude timing (the fitness targets "
                     "come from the Froude number)");
  }
  targets_ = froude_targets(seed_.froude->number, seed_.froude->hip_height_m);
  const auto means = curve_means(seed_);
  for (const auto& stage : config_.freedom) {
    std::vector<std::string> held = means;
    for (const auto& name : stage.free) {
      const auto it = std::find_if(seed_.curves.begin(), seed_.curves.end(),
                                   [&](const GaitCurve& c) { return c.name == name; });
      if (it == seed_.curves.end()) {
        throw InputError(stage.where, "fitness.freedom.free",
                         "no curve '" + name + "' in the seed gait " + seed_.file);
      }
      held[static_cast<std::size_t>(it - seed_.curves.begin())].clear();
    }
    held_.push_back(std::move(held));
  }
}

int Search::stage_at(int generation) const {
  int stage = 0;
  for (std::size_t i = 0; i < config_.freedom.size(); ++i) {
    if (config_.freedom[i].from_generation <= generation) stage = static_cast<int>(i);
  }
  return stage;
}

void Search::evaluate(std::vector<Individual>& pop, int generation, GenerationStats& stats) {
  const int stage = stage_at(generation);
  static const std::vector<std::string> kNoneHeld;
  const auto& held = held_.empty() ? kNoneHeld : held_[static_cast<std::size_t>(stage)];
  const MapLimits limits{config_.search.max_wraps};
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < pop.size(); ++i) {
    Individual& ind = pop[i];
    if (ind.stage == stage) continue;  // an elite already walked under these rules
    if (ind.stage < 0) {
      const MapResult m = map_genome(grammar_, ind.genome, limits);
      ind.mapped = m.valid;
      ind.phenotype = m.phenotype;
    }
    ind.valid = ind.mapped;
    ind.stage = stage;
    if (ind.valid) {
      PhenotypeGait pg = make_phenotype_gait(seed_, ind.phenotype, held);
      ind.valid = pg.valid;
      if (pg.valid) {
        ind.gait = std::move(pg.gait);
        ind.gait.name = config_.name;
      }
    }
    ind.measures = GaitMeasures{};
    if (ind.valid) todo.push_back(i);
  }
  std::vector<const GaitFile*> gaits;
  for (auto i : todo) gaits.push_back(&pop[i].gait);
  std::vector<GaitMeasures> measures(gaits.size());
  const auto t0 = std::chrono::steady_clock::now();
  evaluator_.walk_all(gaits, config_.walk, measures);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stats.evaluations = static_cast<int>(todo.size());
  for (std::size_t k = 0; k < todo.size(); ++k) pop[todo[k]].measures = measures[k];

  // Scores follow the generation's weights, also for elites walked earlier.
  const FitnessWeights& w = weights_at(config_.weights, generation);
  for (auto& ind : pop) {
    ind.fitness = ind.valid ? score(ind.measures, targets_, w, model_.mass_kg) : kWorstFitness;
  }
}

SearchResult Search::run(const std::function<void(const GenerationStats&)>& progress) {
  SearchHooks hooks;
  if (progress) hooks.generation = [&progress](const GenerationStats& st, const Individual&) {
    progress(st);
  };
  return run(hooks);
}

SearchResult Search::run(const SearchHooks& hooks) {
  const SearchSettings& s = config_.search;
  Rng rng(s.seed);
  std::vector<Individual> pop;
  for (auto& g : ramped_full_grow(grammar_, s.population, s.init, rng)) {
    Individual ind;
    ind.genome = std::move(g);
    pop.push_back(std::move(ind));
  }
  SearchResult result;
  for (int gen = 0;; ++gen) {
    GenerationStats st;
    st.generation = gen;
    evaluate(pop, gen, st);
    std::vector<std::size_t> order(pop.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return pop[a].fitness < pop[b].fitness; });
    double sum = 0, sum2 = 0;
    for (const auto& ind : pop) {
      sum += ind.fitness;
      sum2 += ind.fitness * ind.fitness;
      if (!ind.valid) ++st.invalid;
      if (ind.valid && ind.measures.fell) ++st.fell;
    }
    const double n = static_cast<double>(pop.size());
    st.average = sum / n;
    st.stddev = std::sqrt(std::max(0.0, sum2 / n - st.average * st.average));
    const Individual& best = pop[order.front()];
    st.best = best.fitness;
    st.best_phenotype = best.phenotype;
    st.best_measures = best.measures;
    result.evaluations += st.evaluations;
    result.invalid += st.invalid;
    result.history.push_back(st);
    if (hooks.generation) hooks.generation(st, best);
    if (gen >= s.generations) {
      result.best = best;
      break;
    }
    if (hooks.stop && hooks.stop()) {
      result.best = best;
      result.stopped = true;
      break;
    }

    // Next generation: elites, then offspring of tournament winners.
    std::vector<double> fitness(pop.size());
    for (std::size_t i = 0; i < pop.size(); ++i) fitness[i] = pop[i].fitness;
    std::vector<Individual> next;
    next.reserve(pop.size());
    for (int e = 0; e < s.elites; ++e) next.push_back(pop[order[static_cast<std::size_t>(e)]]);
    while (next.size() < pop.size()) {
      Genome a = pop[static_cast<std::size_t>(tournament(fitness, s.tournament, rng))].genome;
      Genome b = pop[static_cast<std::size_t>(tournament(fitness, s.tournament, rng))].genome;
      fixed_point_crossover(a, b, s.crossover, rng);
      int_flip_mutation(a, s.mutation, s.init.codon_size, rng);
      int_flip_mutation(b, s.mutation, s.init.codon_size, rng);
      for (Genome* g : {&a, &b}) {
        if (next.size() >= pop.size()) break;
        Individual child;
        child.genome = std::move(*g);
        next.push_back(std::move(child));
      }
    }
    pop = std::move(next);
  }
  return result;
}

}  // namespace animrt::evolve
