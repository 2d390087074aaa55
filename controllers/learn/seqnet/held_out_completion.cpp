#include "animrt/learn/seqnet/held_out_completion.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/controllers/seqnet/generation.hpp"
#include "animrt/controllers/seqnet/inference.hpp"
#include "animrt/controllers/seqnet/placement.hpp"
#include "animrt/learn/seqnet/interpolation.hpp"

namespace animrt::seqnet {
namespace {

// One held-out segment's frames (normalised, dims x count).
Eigen::MatrixXf segment_frames(const Segment& s, int dims) {
  return Eigen::Map<const Eigen::MatrixXf>(s.values.data(), dims, s.count);
}

struct Sums {
  double network = 0.0, interpolation = 0.0;
  int frames = 0, gaps = 0;
};

void measure_segment(SeqNetInference& net, const Eigen::MatrixXf& truth, int gap, bool blend,
                     Sums& sums) {
  const int keys = (static_cast<int>(truth.cols()) - 1) / (gap + 1) + 1;
  if (keys < 2) return;
  Eigen::MatrixXf key_frames(truth.rows(), keys);
  for (int k = 0; k < keys; ++k) key_frames.col(k) = truth.col(k * (gap + 1));
  const Completion c = net.complete(net.denormalise(key_frames),
                                    std::vector<int>(static_cast<std::size_t>(keys - 1), gap),
                                    {.threshold = 0.05, .retries = 0, .seed = 1, .blend = blend});
  const Eigen::MatrixXf done = net.normalise(c.frames);
  for (int k = 0; k + 1 < keys; ++k) {
    for (int t = 1; t <= gap; ++t) {
      const int f = k * (gap + 1) + t;
      const float s = static_cast<float>(t) / static_cast<float>(gap + 1);
      const Eigen::VectorXf line = (1.0F - s) * key_frames.col(k) + s * key_frames.col(k + 1);
      sums.network += SeqNetInference::frame_difference(done.col(f), truth.col(f));
      sums.interpolation += SeqNetInference::frame_difference(line, truth.col(f));
      ++sums.frames;
    }
    ++sums.gaps;
  }
}

}  // namespace

void add_placed_completion(const ModelFile& model, const std::string& model_path,
                           SeqNetInference& net, const std::vector<Positions>& frames, int gap,
                           const CompletionOptions& options, PlacedCompletion& sums) {
  const int keys = (static_cast<int>(frames.size()) - 1) / (gap + 1) + 1;
  if (keys < 2) return;
  std::vector<Positions> key_meshes;
  for (int k = 0; k < keys; ++k)
    key_meshes.push_back(frames[static_cast<std::size_t>(k * (gap + 1))]);
  const FrameMatrix features =
      mesh_features(model, model_path, key_meshes, model.triangles, gap + 1.0);
  const Completion done =
      net.complete(features, std::vector<int>(static_cast<std::size_t>(keys - 1), gap), options);
  const std::vector<Positions> out = completed_mesh(model, key_meshes, features, done, gap);
  for (int k = 0; k + 1 < keys; ++k) {
    for (int t = 1; t <= gap; ++t) {
      const auto f = static_cast<std::size_t>(k * (gap + 1) + t);
      const double s = static_cast<double>(t) / (gap + 1);
      sums.network += absolute_error(frames[f], out[f]).mean;
      sums.interpolation +=
          absolute_error(frames[f], lerp_positions(key_meshes[static_cast<std::size_t>(k)],
                                                   key_meshes[static_cast<std::size_t>(k + 1)], s))
              .mean;
      ++sums.frames;
    }
  }
}

HeldOutCompletion measure_held_out_completion(const ModelFile& model, const TrainingSet& set,
                                              int max_gap, bool blend) {
  HeldOutCompletion out;
  int longest = 0;
  for (const Segment& s : set.segments) {
    if (s.held_out) longest = std::max(longest, s.count);
  }
  out.gap = std::min(max_gap, longest - 2);
  if (out.gap < 1) return out;
  SeqNetInference net(model, "the model in training");
  Sums sums;
  for (const Segment& s : set.segments) {
    if (s.held_out) measure_segment(net, segment_frames(s, set.dims), out.gap, blend, sums);
  }
  if (sums.frames == 0) return out;
  out.gaps = sums.gaps;
  out.network = sums.network / sums.frames;
  out.interpolation = sums.interpolation / sums.frames;
  if (!std::isfinite(out.network)) out.network = -1.0;  // never counted better
  if (model.shape.placement_nodes == 0) return out;
  PlacedCompletion placed;
  const CompletionOptions options{.threshold = 0.05, .retries = 0, .seed = 1, .blend = blend};
  for (const Segment& s : set.segments) {
    if (s.held_out && !s.placed.empty()) {
      add_placed_completion(model, "the model in training", net, s.placed, out.gap, options,
                            placed);
    }
  }
  if (placed.frames > 0 && std::isfinite(placed.network)) {
    out.placed = placed.network / placed.frames;
    out.placed_interpolation = placed.interpolation / placed.frames;
  }
  return out;
}

}  // namespace animrt::seqnet
