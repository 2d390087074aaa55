// Herd run speed as a multiple of real time: whole herd steps (steering,
// figures, contact guard) for 50, 200 and 1,000 figures in a mixed scene
// (a Reynolds flock, two crowds crossing it) and for flocks alone.

#include <benchmark/benchmark.h>

#include <string>

#include "animrt/controllers/herd/herd.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace {

using namespace animrt::herd;

std::string gait_of(const std::string& robot) {
  return animrt::load_robot_config(robot).motion.file;
}

// The shipped pasture scene with its groups resized to `n` figures (half
// flock, a quarter per crowd) and its ground grown to keep the density.
HerdScene scene_of(int n, bool crowds) {
  HerdScene s = load_herd_scene(std::string(ANIMRT_SOURCE_DIR) + "/configs/herd/pasture.yaml");
  const double k = std::sqrt(n / 50.0);
  s.bounds_m = {s.bounds_m.xmin * k, s.bounds_m.ymin * k, s.bounds_m.xmax * k, s.bounds_m.ymax * k};
  s.walls.clear();
  for (GroupSpec& g : s.groups) {
    // A flock alone has all n figures in its spawn area: twice the room.
    const double ks = crowds || g.kind == GroupKind::crowd ? k : k * std::sqrt(2.0);
    g.spawn_m = {g.spawn_m.xmin * ks, g.spawn_m.ymin * ks, g.spawn_m.xmax * ks,
                 g.spawn_m.ymax * ks};
    if (g.target_m) g.target_m = Vec2{g.target_m->x * k, g.target_m->y * k};
    if (g.leader) {
      Rect& w = g.leader->wander_m;
      w = {w.xmin * k, w.ymin * k, w.xmax * k, w.ymax * k};
    }
  }
  if (crowds) {
    s.groups[0].count = n / 2;
    s.groups[1].count = n / 4;
    s.groups[2].count = n - n / 2 - n / 4;
  } else {
    s.groups.resize(1);
    s.groups[0].count = n;
  }
  return s;
}

void run(benchmark::State& state, bool crowds) {
  Herd herd(scene_of(static_cast<int>(state.range(0)), crowds), gait_of);
  for (int k = 0; k < 50; ++k) herd.step();  // past the first crowded steps
  for (auto _ : state) herd.step();
  const double sim_s = static_cast<double>(state.iterations()) * herd.scene().step_s;
  state.counters["sim_s_per_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
  state.counters["agents"] = static_cast<double>(herd.agents().size());
}

void BM_HerdMixed(benchmark::State& state) { run(state, true); }
void BM_HerdFlock(benchmark::State& state) { run(state, false); }

BENCHMARK(BM_HerdMixed)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_HerdFlock)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
