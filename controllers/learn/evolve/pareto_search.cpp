// NSGA-II over GE genomes (see pareto_search.hpp).

#include "animrt/learn/evolve/pareto_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace animrt::evolve {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kGravity = 9.81;

// Rank (front index) and crowding distance of every point.
struct Ranking {
  std::vector<int> rank;
  std::vector<double> crowding;
  std::vector<std::vector<int>> fronts;
};

Ranking rank_points(const std::vector<Objectives>& points) {
  Ranking r;
  r.rank.assign(points.size(), 0);
  r.crowding.assign(points.size(), 0.0);
  r.fronts = non_dominated_fronts(points);
  for (std::size_t f = 0; f < r.fronts.size(); ++f) {
    const auto& front = r.fronts[f];
    const auto d = crowding_distance(points, front);
    for (std::size_t k = 0; k < front.size(); ++k) {
      r.rank[static_cast<std::size_t>(front[k])] = static_cast<int>(f);
      r.crowding[static_cast<std::size_t>(front[k])] = d[k];
    }
  }
  return r;
}

// The crowded comparison: lower front first, then the less crowded.
bool crowded_better(const Ranking& r, int a, int b) {
  const auto ia = static_cast<std::size_t>(a), ib = static_cast<std::size_t>(b);
  if (r.rank[ia] != r.rank[ib]) return r.rank[ia] < r.rank[ib];
  return r.crowding[ia] > r.crowding[ib];
}

int binary_tournament(const Ranking& r, std::size_t n, Rng& rng) {
  const int a = rng.index(n);
  const int b = rng.index(n);
  if (crowded_better(r, b, a)) return b;
  return a;
}

bool walked(const Individual& ind) { return ind.valid && !ind.measures.fell; }

}  // namespace

Objectives pareto_objectives(const Individual& ind, const GaitTargets& targets, double mass_kg) {
  if (!walked(ind)) return Objectives(kParetoObjectives, kInf);
  const GaitMeasures& m = ind.measures;
  return {std::fabs(m.speed - targets.speed) / targets.speed,
          m.energy_per_cycle / (mass_kg * kGravity * targets.stride_length), m.max_tilt_deg};
}

ParetoSearch::ParetoSearch(RunConfig config, Grammar grammar, GaitFile seed, ModelInfo model,
                           Evaluator& evaluator)
    : config_(std::move(config)),
      grammar_(std::move(grammar)),
      seed_(std::move(seed)),
      model_(std::move(model)),
      evaluator_(evaluator),
      walker_(config_, grammar_, seed_) {
  targets_ = froude_targets(seed_.froude->number, seed_.froude->hip_height_m);
}

ParetoResult ParetoSearch::run(const std::function<void(const ParetoGeneration&)>& progress) {
  const SearchSettings& s = config_.search;
  Rng rng(s.seed);
  std::vector<Individual> pop = initial_population(grammar_, s, rng);
  ParetoResult result;
  const auto objectives_of = [&](const std::vector<Individual>& p) {
    std::vector<Objectives> out;
    out.reserve(p.size());
    for (const auto& ind : p) out.push_back(pareto_objectives(ind, targets_, model_.mass_kg));
    return out;
  };

  std::vector<Objectives> points;
  Ranking ranking;
  for (int gen = 0;; ++gen) {
    ParetoGeneration st;
    st.generation = gen;
    const int stage = walker_.stage_at(gen);
    if (gen == 0) {
      const WalkBatch b = walker_.walk(pop, stage, evaluator_);
      st.evaluations = b.evaluations;
      st.seconds = b.seconds;
    } else {
      // Offspring of crowded-tournament winners, walked, then parents and
      // offspring together compete for the N places.
      std::vector<Individual> children;
      children.reserve(pop.size());
      breed(
          pop,
          [&] { return static_cast<std::size_t>(binary_tournament(ranking, pop.size(), rng)); }, s,
          pop.size(), children, rng);
      for (auto& c : children) pop.push_back(std::move(c));
      // Parents walked under an earlier freedom stage walk again.
      const WalkBatch b = walker_.walk(pop, stage, evaluator_);
      st.evaluations = b.evaluations;
      st.seconds = b.seconds;
      const Ranking all = rank_points(objectives_of(pop));
      std::vector<int> keep;
      for (const auto& front : all.fronts) {
        if (keep.size() + front.size() <= static_cast<std::size_t>(s.population)) {
          keep.insert(keep.end(), front.begin(), front.end());
          continue;
        }
        std::vector<int> last = front;
        std::stable_sort(last.begin(), last.end(), [&](int x, int y) {
          return all.crowding[static_cast<std::size_t>(x)] >
                 all.crowding[static_cast<std::size_t>(y)];
        });
        last.resize(static_cast<std::size_t>(s.population) - keep.size());
        keep.insert(keep.end(), last.begin(), last.end());
        break;
      }
      std::vector<Individual> next;
      next.reserve(keep.size());
      for (int i : keep) next.push_back(std::move(pop[static_cast<std::size_t>(i)]));
      pop = std::move(next);
    }
    points = objectives_of(pop);
    ranking = rank_points(points);

    st.best_speed_error = st.best_energy = st.best_tilt_deg = kInf;
    for (std::size_t i = 0; i < pop.size(); ++i) {
      if (!pop[i].valid) ++st.invalid;
      if (pop[i].valid && pop[i].measures.fell) ++st.fell;
      if (ranking.rank[i] == 0 && walked(pop[i])) {
        ++st.front_size;
        st.best_speed_error = std::min(st.best_speed_error, points[i][0]);
        st.best_energy = std::min(st.best_energy, points[i][1]);
        st.best_tilt_deg = std::min(st.best_tilt_deg, points[i][2]);
      }
    }
    result.evaluations += st.evaluations;
    result.history.push_back(st);
    if (progress) progress(st);
    if (gen >= s.generations) break;
  }

  // Copies of one phenotype (a parent and its unchanged child) are one gait.
  for (std::size_t i = 0; i < pop.size(); ++i) {
    if (ranking.rank[i] != 0 || !walked(pop[i])) continue;
    const bool copy = std::any_of(result.front.begin(), result.front.end(), [&](const auto& m) {
      return m.individual.phenotype == pop[i].phenotype;
    });
    if (!copy) result.front.push_back({pop[i], points[i]});
  }
  std::stable_sort(result.front.begin(), result.front.end(),
                   [](const ParetoMember& a, const ParetoMember& b) {
                     return a.objectives[0] < b.objectives[0];
                   });
  return result;
}

}  // namespace animrt::evolve
