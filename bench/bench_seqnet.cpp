// Deformation features: extraction (per-vertex fits, exact round-trip
// correction, polar split, consistent rotations) and reconstruction time
// per frame on twisting bars of about 500, 2,500 and 10,000 vertices. The
// one-off factorisation per connectivity is timed separately.

#include <benchmark/benchmark.h>

#include <numbers>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/controllers/seqnet/shapes.hpp"

using namespace animrt::seqnet;

namespace {

// rings x around + 2 vertices: 502, 2,502, 10,002.
MeshSequence bar_for(int vertices) {
  const int around = vertices <= 600 ? 20 : vertices <= 3000 ? 50 : 100;
  const int rings = (vertices - 2) / around;
  return make_twisting_bar(rings, around, 8.0, 1.5 * std::numbers::pi, 2);
}

void BM_Factorise(benchmark::State& state) {
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Reconstructor solver(bar.frames[0], bar.triangles);
    benchmark::DoNotOptimize(&solver);
  }
}

void BM_FeaturesPerFrame(benchmark::State& state) {
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  const Reconstructor solver(bar.frames[0], bar.triangles);
  const FeatureFrame previous = FeatureFrame::Zero(kFeatureDims, bar.vertex_count());
  for (auto _ : state) {
    auto gradients =
        deformation_gradients(solver.neighbourhood(), bar.triangles, bar.frames[0], bar.frames[1]);
    gradients = solver.exact_gradients(gradients, bar.frames[1]);
    FeatureFrame f = features_from_gradients(gradients, solver.neighbourhood(), previous);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["vertices"] = bar.vertex_count();
}

void BM_ReconstructPerFrame(benchmark::State& state) {
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  const SequenceFeatures features = compute_features(bar);
  const Reconstructor solver(features.rest, features.triangles);
  const FeatureFrame raw = features.raw(1);
  for (auto _ : state) {
    Positions p = solver.solve(raw);
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["vertices"] = bar.vertex_count();
}

}  // namespace

BENCHMARK(BM_Factorise)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeaturesPerFrame)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReconstructPerFrame)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
