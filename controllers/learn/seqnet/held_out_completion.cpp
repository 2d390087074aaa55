#include "animrt/learn/seqnet/held_out_completion.hpp"

#include <algorithm>
#include <cmath>

#include "animrt/controllers/seqnet/inference.hpp"

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
  return out;
}

}  // namespace animrt::seqnet
