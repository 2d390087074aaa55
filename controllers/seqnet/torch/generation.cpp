#include "animrt/controllers/seqnet/generation.hpp"

#include <torch/torch.h>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/network.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"

namespace animrt::seqnet {

std::vector<Positions> generate_mesh(const ModelFile& model, const std::string& model_path,
                                     const std::vector<Positions>& initial,
                                     const std::vector<std::array<int, 3>>& triangles,
                                     const GenerateOptions& options) {
  torch::set_num_threads(std::max(1, options.threads));
  const int u = static_cast<int>(initial.size());
  if (u < 1) throw InputError(Location{model_path, 0, 0}, "--init", "no initial frame");
  for (const Positions& p : initial) {
    check_model_mesh(model, model_path, static_cast<int>(p.cols()), triangles);
  }
  if (u >= model.shape.window) {
    throw InputError(Location{model_path, 0, 0}, "--init",
                     std::to_string(u) + " initial frames, the model's window is " +
                         std::to_string(model.shape.window) + " frames");
  }
  // Features of the initial frames against the model's template, mapped as
  // in training.
  MeshSequence seq;
  seq.triangles = model.triangles;
  seq.frames.push_back(model.rest);
  for (const Positions& p : initial) seq.frames.push_back(p);
  const SequenceFeatures f = compute_features(seq);
  FeatureScale scale;
  const int v = model.shape.vertex_count;
  scale.low = Eigen::Map<const FeatureFrame>(model.low.data(), kFeatureDims, v);
  scale.high = Eigen::Map<const FeatureFrame>(model.high.data(), kFeatureDims, v);
  const std::int64_t d = model.shape.input_dims();
  torch::Tensor all = torch::empty({u, 1, d});
  for (int k = 0; k < u; ++k) {
    const FeatureFrame x = scale.normalise(f.raw(k + 1));
    const Eigen::Matrix<float, kFeatureDims, Eigen::Dynamic> xf = x.cast<float>();
    all[k][0].copy_(torch::from_blob(const_cast<float*>(xf.data()), {d}, torch::kFloat32));
  }

  SeqNet net = network_for(model, model_path);
  net->eval();
  torch::NoGradGuard no_grad;
  torch::Generator gen =
      torch::make_generator<at::CPUGeneratorImpl>(options.random_state.value_or(0));
  const int total = u + options.frames;
  while (all.size(0) < total) {
    const std::int64_t have = all.size(0);
    const int n = static_cast<int>(std::min<std::int64_t>(model.shape.window, u + total - have));
    LstmState state = net->initial_state(1, 1.0);
    if (options.random_state) {
      const double s0 = model.shape.s0;
      auto draw = [&] {
        return torch::normal(s0, std::abs(s0), {model.shape.lstm_layers, 1, model.shape.hidden},
                             gen);
      };
      state = LstmState{draw(), draw()};
    }
    const torch::Tensor context = all.slice(0, have - u, have);
    const Chain c = net->run(context, n, state, false);
    all = torch::cat({all, c.frames.slice(0, u, n)});
  }

  const Reconstructor solver(model.rest, model.triangles);
  std::vector<Positions> out;
  for (int k = 0; k < total; ++k) {
    const torch::Tensor t = all[k][0].contiguous().to(torch::kFloat64);
    const FeatureFrame x = Eigen::Map<const FeatureFrame>(t.data_ptr<double>(), kFeatureDims, v);
    out.push_back(k < u ? initial[static_cast<std::size_t>(k)]
                        : solver.solve(scale.denormalise(x)));
  }
  return out;
}

}  // namespace animrt::seqnet
