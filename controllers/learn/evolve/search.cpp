// The generational GE loop (see search.hpp).

#include "animrt/learn/evolve/search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace animrt::evolve {

Search::Search(RunConfig config, Grammar grammar, GaitFile seed, ModelInfo model,
               Evaluator& evaluator)
    : config_(std::move(config)),
      grammar_(std::move(grammar)),
      seed_(std::move(seed)),
      model_(std::move(model)),
      evaluator_(evaluator),
      walker_(config_, grammar_, seed_) {
  targets_ = froude_targets(seed_.froude->number, seed_.froude->hip_height_m);
}

void Search::evaluate(std::vector<Individual>& pop, int generation, GenerationStats& stats) {
  const WalkBatch batch = walker_.walk(pop, walker_.stage_at(generation), evaluator_);
  stats.seconds = batch.seconds;
  stats.evaluations = batch.evaluations;
  stats.reused = batch.reused;
  // Scores follow the generation's weights, also for elites walked earlier.
  const FitnessWeights& w = weights_at(config_.weights, generation);
  for (auto& ind : pop) {
    ind.fitness = ind.valid ? score(ind.measures, targets_, w, model_.mass_kg) : kWorstFitness;
  }
}

SearchResult Search::run(const std::function<void(const GenerationStats&)>& progress) {
  SearchHooks hooks;
  if (progress)
    hooks.generation = [&progress](const GenerationStats& st, const Individual&) { progress(st); };
  return run(hooks);
}

SearchResult Search::run(const SearchHooks& hooks) {
  const SearchSettings& s = config_.search;
  Rng rng(s.seed);
  std::vector<Individual> pop = initial_population(grammar_, s, rng);
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
    result.reused += st.reused;
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
    breed(
        pop, [&] { return static_cast<std::size_t>(tournament(fitness, s.tournament, rng)); }, s,
        pop.size(), next, rng);
    pop = std::move(next);
  }
  return result;
}

}  // namespace animrt::evolve
