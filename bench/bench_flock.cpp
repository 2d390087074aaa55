// Flock steering: agent-steps per second for herds of 100, 1,000 and 10,000
// figures at pony spacing (about one per 0.64 m^2), each variant with the
// grid neighbour search and with the all-pairs scan it replaces (compare the
// pairs: all-pairs / grid time is the grid's speed-up).

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "animrt/controllers/herd/pony_params.hpp"
#include "animrt/controllers/herd/reynolds_flock.hpp"
#include "animrt/controllers/herd/unity_flock.hpp"

namespace {

using namespace animrt::herd;

std::vector<Agent> herd(int n) {
  std::mt19937_64 rng(1);
  const double side = 0.8 * std::sqrt(static_cast<double>(n));
  std::uniform_real_distribution<double> u(0.0, side);
  std::uniform_real_distribution<double> h(-3.14159, 3.14159);
  std::vector<Agent> a(static_cast<std::size_t>(n));
  for (Agent& x : a) {
    x.position = {u(rng), u(rng)};
    x.heading = h(rng);
    x.speed = 0.08;
  }
  return a;
}

WanderLeader leader(int n) {
  WanderParams w;
  w.speed = 0.08;
  const double side = 0.8 * std::sqrt(static_cast<double>(n));
  w.wander_m = {0, 0, side, side};
  w.reach_m = 1.0;
  return WanderLeader(w, {side / 2, side / 2}, 0.0, 2);
}

std::vector<int> all_members(int n) {
  std::vector<int> m(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) m[static_cast<std::size_t>(i)] = i;
  return m;
}

template <class Flock, class Params>
void run(benchmark::State& state, const Params& p, NeighbourSearch search) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<Agent> a = herd(n);
  Flock f(all_members(n), p, leader(n), 3);
  f.set_neighbour_search(search);
  std::vector<Vec2> d(a.size());
  double t = 0.0;
  for (auto _ : state) {
    f.steer(t, 0.1, a, d);
    t += 0.1;
    benchmark::DoNotOptimize(d.data());
  }
  state.counters["agent_steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n, benchmark::Counter::kIsRate);
}

// The pony-size parameters the flock tests and the shipped scenes use.
ReynoldsFlockParams reynolds() { return pony_reynolds(); }
UnityFlockParams unity() { return pony_unity(); }

void BM_ReynoldsGrid(benchmark::State& s) {
  run<ReynoldsFlock>(s, reynolds(), NeighbourSearch::grid);
}
void BM_ReynoldsAllPairs(benchmark::State& s) {
  run<ReynoldsFlock>(s, reynolds(), NeighbourSearch::all_pairs);
}
void BM_UnityGrid(benchmark::State& s) { run<UnityFlock>(s, unity(), NeighbourSearch::grid); }
void BM_UnityAllPairs(benchmark::State& s) {
  run<UnityFlock>(s, unity(), NeighbourSearch::all_pairs);
}

BENCHMARK(BM_ReynoldsGrid)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ReynoldsAllPairs)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_UnityGrid)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_UnityAllPairs)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
