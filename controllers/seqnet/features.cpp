#include "animrt/controllers/seqnet/features.hpp"

#include <algorithm>
#include <queue>
#include <stdexcept>

#include "animrt/controllers/seqnet/placement.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"

namespace animrt::seqnet {

FeatureFrame features_from_gradients(const std::vector<Eigen::Matrix3d>& gradients,
                                     const Neighbourhood& ring, const FeatureFrame& previous) {
  const int v = ring.vertex_count;
  FeatureFrame out(kFeatureDims, v);
  for (int i = 0; i < v; ++i) {
    const Polar p = polar_decomposition(gradients[i]);
    out.block<3, 1>(0, i) = rotation_log(p.rotation);
    const Eigen::Matrix3d& s = p.stretch;
    out.block<6, 1>(3, i) << s(0, 0), s(0, 1), s(0, 2), s(1, 1), s(1, 2), s(2, 2);
  }
  // Consistent rotation vectors: breadth-first over each piece.
  std::vector<char> done(static_cast<std::size_t>(v), 0);
  std::queue<int> open;
  for (int seed = 0; seed < v; ++seed) {
    if (done[seed]) continue;
    out.block<3, 1>(0, seed) =
        closest_equivalent(out.block<3, 1>(0, seed), previous.block<3, 1>(0, seed));
    done[seed] = 1;
    open.push(seed);
    while (!open.empty()) {
      const int p = open.front();
      open.pop();
      const Eigen::Vector3d change = out.block<3, 1>(0, p) - previous.block<3, 1>(0, p);
      for (int k = ring.offsets[p]; k < ring.offsets[p + 1]; ++k) {
        const int j = ring.neighbours[k];
        if (done[j]) continue;
        const Eigen::Vector3d reference = previous.block<3, 1>(0, j) + change;
        out.block<3, 1>(0, j) = closest_equivalent(out.block<3, 1>(0, j), reference);
        done[j] = 1;
        open.push(j);
      }
    }
  }
  return out;
}

Eigen::Matrix3d gradient_of(const FeatureFrame& f, int i) {
  Eigen::Matrix3d s;
  s << f(3, i), f(4, i), f(5, i), f(4, i), f(6, i), f(7, i), f(5, i), f(7, i), f(8, i);
  return rotation_exp(f.block<3, 1>(0, i)) * s;
}

FeatureScale FeatureScale::fit(const std::vector<FeatureFrame>& raw) {
  if (raw.empty()) throw std::invalid_argument("FeatureScale::fit: no frames");
  FeatureScale out{raw.front(), raw.front()};
  for (const auto& f : raw) {
    out.low = out.low.cwiseMin(f);
    out.high = out.high.cwiseMax(f);
  }
  return out;
}

FeatureFrame FeatureScale::normalise(const FeatureFrame& raw) const {
  FeatureFrame out(kFeatureDims, raw.cols());
  for (Eigen::Index i = 0; i < raw.size(); ++i) {
    const double range = high(i) - low(i);
    out(i) = range > 0.0 ? (raw(i) - low(i)) / range * 1.9 - 0.95 : raw(i) - low(i);
  }
  return out;
}

FeatureFrame FeatureScale::denormalise(const FeatureFrame& normalised) const {
  FeatureFrame out(kFeatureDims, normalised.cols());
  for (Eigen::Index i = 0; i < normalised.size(); ++i) {
    const double range = high(i) - low(i);
    out(i) = range > 0.0 ? (normalised(i) + 0.95) / 1.9 * range + low(i) : normalised(i) + low(i);
  }
  return out;
}

SequenceFeatures compute_features(const MeshSequence& sequence, int first, int count,
                                  bool exact_round_trip) {
  if (sequence.frames.empty()) throw std::invalid_argument("compute_features: no frames");
  if (count == 0) count = sequence.frame_count() - first;
  if (first < 0 || count < 1 || first + count > sequence.frame_count()) {
    throw std::invalid_argument("compute_features: frames out of range");
  }
  SequenceFeatures out;
  out.rest = sequence.frames.front();
  out.triangles = sequence.triangles;
  const Reconstructor solver(out.rest, out.triangles);
  const Neighbourhood& ring = solver.neighbourhood();
  FeatureFrame previous = FeatureFrame::Zero(kFeatureDims, out.rest.cols());
  std::vector<FeatureFrame> raw;
  raw.reserve(static_cast<std::size_t>(count));
  // Clips are separate motions: the pose jumps where one ends and the next
  // begins, so each clip's first frame starts again from the template and
  // takes its rotations from the walk over the mesh alone.
  std::vector<char> clip_start(static_cast<std::size_t>(sequence.frame_count()), 0);
  for (const Clip& c : sequence.clips) {
    if (c.first >= 0 && c.first < sequence.frame_count()) clip_start[c.first] = 1;
  }
  const FeatureFrame from_template = previous;
  for (int f = first; f < first + count; ++f) {
    if (clip_start[f]) previous = from_template;
    auto gradients = deformation_gradients(ring, out.triangles, out.rest, sequence.frames[f]);
    if (exact_round_trip) gradients = solver.exact_gradients(gradients, sequence.frames[f]);
    raw.push_back(features_from_gradients(gradients, ring, previous));
    previous = raw.back();
    out.placement.push_back(placement_of(ring, sequence.frames[f]));
  }
  out.scale = FeatureScale::fit(raw);
  for (const auto& f : raw) out.frames.push_back(out.scale.normalise(f));
  for (const Clip& c : sequence.clips) {
    if (c.first >= first && c.first + c.count <= first + count) {
      Clip moved = c;
      moved.first -= first;
      out.clips.push_back(moved);
    }
  }
  return out;
}

}  // namespace animrt::seqnet
