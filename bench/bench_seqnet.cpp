// Deformation features: extraction (per-vertex fits, exact round-trip
// correction, polar split, consistent rotations) and reconstruction time
// per frame on twisting bars of about 500, 2,500 and 10,000 vertices. The
// one-off factorisation per connectivity is timed separately.
// The sequence network (libtorch, one thread): seconds per training
// iteration at the paper's size (batch 8, 32 frames, both chains, Adam) on
// meshes of about 500 and 2,500 vertices, against a bare libtorch LSTM of
// the same size (3 x 128, linear maps in and out of the 9 V features) doing
// the same chains; and generation time per frame, mesh and joint space, on
// libtorch and on the plain C++ inference that animrt runs (the same
// randomly initialised network).

#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <numbers>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/learn/seqnet/network.hpp"
#include "animrt/learn/seqnet/shapes.hpp"

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

NetShape mesh_shape(const MeshSequence& bar) {
  NetShape s;
  s.kind = ModelKind::mesh;
  s.vertex_count = bar.vertex_count();
  return s;
}

void BM_TrainIteration(benchmark::State& state) {
  torch::set_num_threads(1);
  torch::manual_seed(1);
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  SeqNet net(mesh_shape(bar), mesh_graph(bar.vertex_count(), bar.triangles));
  Adam adam(net->parameters(), 1e-3);
  const torch::Tensor truth = torch::rand({32, 8, 9 * bar.vertex_count()}) * 1.9 - 0.95;
  for (auto _ : state) {
    const LossTerms l = batch_loss(net, truth, true);
    l.total.backward();
    adam.step();
  }
  state.counters["vertices"] = bar.vertex_count();
}

// The same chains through a plain LSTM: linear in, 3 x 128 LSTM, linear out.
void BM_BareLstmIteration(benchmark::State& state) {
  torch::set_num_threads(1);
  torch::manual_seed(1);
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  const std::int64_t d = 9 * bar.vertex_count();
  torch::nn::Linear in(d, 128), out(128, d);
  torch::nn::LSTM lstm(torch::nn::LSTMOptions(128, 128).num_layers(3));
  std::vector<torch::Tensor> params = lstm->parameters();
  for (const auto& p : in->parameters()) params.push_back(p);
  for (const auto& p : out->parameters()) params.push_back(p);
  Adam adam(params, 1e-3);
  const torch::Tensor truth = torch::rand({32, 8, d}) * 1.9 - 0.95;
  auto chain = [&](torch::Tensor x, double sign) {
    LstmState s{torch::full({3, 8, 128}, 0.1 * sign), torch::full({3, 8, 128}, 0.1 * sign)};
    std::vector<torch::Tensor> frames{x};
    for (int t = 1; t < 32; ++t) {
      auto [o, next] = lstm->forward(in->forward(x).unsqueeze(0), s);
      s = next;
      x = x + out->forward(o.squeeze(0));
      frames.push_back(x);
    }
    return torch::stack(frames);
  };
  for (auto _ : state) {
    const torch::Tensor f = chain(truth[0], 1.0), b = chain(truth[31], -1.0);
    const torch::Tensor loss = recon_loss(f, b, truth) + 0.5 * bidir_loss(f, b);
    loss.backward();
    adam.step();
  }
  state.counters["vertices"] = bar.vertex_count();
}

// One generated frame: encode, one LSTM step, decode, add.
void generate_frames(benchmark::State& state, const NetShape& shape, const MeshGraph& graph) {
  torch::set_num_threads(1);
  torch::manual_seed(1);
  SeqNet net(shape, graph);
  torch::NoGradGuard no_grad;
  torch::Tensor x = torch::zeros({1, shape.input_dims()});
  LstmState s = net->initial_state(1, 1.0);
  for (auto _ : state) {
    auto [mu, logvar] = net->encode(x);
    auto [o, next] = net->lstm->forward(mu.unsqueeze(0), s);
    s = next;
    x = x + net->decode(o.squeeze(0));
    benchmark::DoNotOptimize(x.data_ptr<float>());
  }
}

void BM_GenerateMeshFrame(benchmark::State& state) {
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  generate_frames(state, mesh_shape(bar), mesh_graph(bar.vertex_count(), bar.triangles));
  state.counters["vertices"] = bar.vertex_count();
}

void BM_GenerateJointFrame(benchmark::State& state) {
  NetShape s;
  s.kind = ModelKind::joints;
  s.joint_count = static_cast<int>(state.range(0));
  generate_frames(state, s, MeshGraph{});
}

// The same step on the plain inference (SeqNetInference::step).
void plain_frames(benchmark::State& state, const NetShape& shape, const MeshSequence* mesh) {
  torch::manual_seed(1);
  ModelFile model;
  model.shape = shape;
  MeshGraph graph;
  if (mesh != nullptr) {
    model.rest = mesh->frames.front();
    model.triangles = mesh->triangles;
    graph = mesh_graph(mesh->vertex_count(), mesh->triangles);
  } else {
    for (int j = 0; j < shape.joint_count; ++j)
      model.joint_names.push_back("j" + std::to_string(j));
  }
  model.low.assign(static_cast<std::size_t>(shape.input_dims()), -1.0);
  model.high.assign(static_cast<std::size_t>(shape.input_dims()), 1.0);
  SeqNet net(shape, graph);
  model.parameters = save_parameters(*net);
  SeqNetInference plain(model, "bench");
  Eigen::VectorXf x = Eigen::VectorXf::Zero(shape.input_dims());
  LstmCellState s = plain.initial_state(1.0);
  for (auto _ : state) {
    plain.step(x, s);
    benchmark::DoNotOptimize(x.data());
  }
}

void BM_PlainMeshFrame(benchmark::State& state) {
  const MeshSequence bar = bar_for(static_cast<int>(state.range(0)));
  plain_frames(state, mesh_shape(bar), &bar);
  state.counters["vertices"] = bar.vertex_count();
}

void BM_PlainJointFrame(benchmark::State& state) {
  NetShape s;
  s.kind = ModelKind::joints;
  s.joint_count = static_cast<int>(state.range(0));
  plain_frames(state, s, nullptr);
}

}  // namespace

BENCHMARK(BM_Factorise)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FeaturesPerFrame)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReconstructPerFrame)->Arg(500)->Arg(2500)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TrainIteration)->Arg(500)->Arg(2500)->Iterations(3)->Unit(benchmark::kSecond);
BENCHMARK(BM_BareLstmIteration)->Arg(500)->Arg(2500)->Iterations(3)->Unit(benchmark::kSecond);
BENCHMARK(BM_GenerateMeshFrame)->Arg(500)->Arg(2500)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GenerateJointFrame)->Arg(12)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlainMeshFrame)->Arg(500)->Arg(2500)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlainJointFrame)->Arg(12)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
