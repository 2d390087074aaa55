// Training speed of the sequence network: iterations per second of the
// step `animrt seq train` runs (train_step: both chains over 8 windows of
// 32 frames with latent sampling, backward, Adam) at the paper's size, on
// twisting bars of 502 and 2,452 vertices, with 1 and 2 libtorch threads.
// Besides wall time it reports the process CPU seconds per iteration
// (`cpu_s`, every thread counted): on a machine shared with other work
// the wall figure varies with the load, the CPU figure much less, and the
// least CPU time of one iteration (`cpu_s_min`) least of all.
// ANIMRT_BENCH_ITERATIONS=N runs N iterations instead of 4.
// Like animrt-seqnet it restarts itself on OpenBLAS's best kernels for the
// CPU (blas_kernels.hpp); OPENBLAS_CORETYPE=Prescott measures the generic
// ones.

#include <benchmark/benchmark.h>
#include <torch/csrc/autograd/profiler_legacy.h>
#include <torch/torch.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <numbers>

#include "animrt/learn/seqnet/blas_kernels.hpp"
#include "animrt/learn/seqnet/memory.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"

using namespace animrt::seqnet;

namespace {

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// rings x around + 2 vertices: 502 or 2,452.
MeshSequence training_bar(int vertices) {
  const int around = vertices <= 600 ? 20 : 50;
  const int rings = (vertices - 2) / around;
  return make_twisting_bar(rings, around, 8.0, 1.5 * std::numbers::pi, 2);
}

void BM_SeqTrainIteration(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(1));
  torch::set_num_threads(threads);
  torch::manual_seed(1);
  const MeshSequence bar = training_bar(static_cast<int>(state.range(0)));
  NetShape shape;
  shape.kind = ModelKind::mesh;
  shape.vertex_count = bar.vertex_count();
  SeqNet net(shape, mesh_graph(bar.vertex_count(), bar.triangles));
  Adam adam(net->parameters(), 1e-3);
  // Random windows in the features' range: the cost does not depend on
  // the values.
  const torch::Tensor truth = torch::rand({32, 8, shape.input_dims()}) * 1.9 - 0.95;
  train_step(net, adam, truth);  // first-use allocations out of the timing
  // ANIMRT_BENCH_PROFILE=FILE: libtorch's account of one more iteration
  // (a Chrome trace: every operation with its time).
  if (const char* file = std::getenv("ANIMRT_BENCH_PROFILE")) {
    torch::autograd::profiler::RecordProfile profile(file);
    train_step(net, adam, truth);
  }
  const double cpu0 = process_cpu_seconds();
  double fastest = 1e30;
  for (auto _ : state) {
    const double start = process_cpu_seconds();
    const LossTerms l = train_step(net, adam, truth);
    benchmark::DoNotOptimize(l.total.item<double>());
    fastest = std::min(fastest, process_cpu_seconds() - start);
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["vertices"] = bar.vertex_count();
  state.counters["threads"] = threads;
  state.counters["it_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["cpu_s"] = (process_cpu_seconds() - cpu0) / n;
  // The least disturbed iteration: on a loaded machine the steadiest figure.
  state.counters["cpu_s_min"] = fastest;
}

// ANIMRT_BENCH_LOSSES=N: the total loss of the first N iterations at 482
// vertices from seed 1, to compare two builds of the network.
void print_losses(int n) {
  torch::set_num_threads(1);
  torch::manual_seed(1);
  const MeshSequence bar = training_bar(500);
  NetShape shape;
  shape.kind = ModelKind::mesh;
  shape.vertex_count = bar.vertex_count();
  SeqNet net(shape, mesh_graph(bar.vertex_count(), bar.triangles));
  Adam adam(net->parameters(), 1e-3);
  const torch::Tensor truth = torch::rand({32, 8, shape.input_dims()}) * 1.9 - 0.95;
  for (int k = 0; k < n; ++k) {
    std::printf("%d %.9g\n", k + 1, train_step(net, adam, truth).total.item<double>());
  }
}

int iterations() {
  const char* n = std::getenv("ANIMRT_BENCH_ITERATIONS");
  return n == nullptr ? 4 : std::max(1, std::atoi(n));
}

}  // namespace

BENCHMARK(BM_SeqTrainIteration)
    ->ArgNames({"vertices", "threads"})
    ->Args({500, 1})
    ->Args({500, 2})
    ->Args({2500, 1})
    ->Args({2500, 2})
    ->Iterations(iterations())
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  restart_with_better_blas_kernels(argv);
  // As animrt-seqnet does; ANIMRT_BENCH_GLIBC_FREE=1 leaves glibc's defaults.
  if (std::getenv("ANIMRT_BENCH_GLIBC_FREE") == nullptr) keep_freed_memory();
  if (const char* n = std::getenv("ANIMRT_BENCH_LOSSES")) {
    print_losses(std::atoi(n));
    return 0;
  }
  benchmark::AddCustomContext("blas_kernels", blas_kernels());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
