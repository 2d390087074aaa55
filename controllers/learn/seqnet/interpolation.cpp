#include "animrt/learn/seqnet/interpolation.hpp"

#include <stdexcept>

namespace animrt::seqnet {
namespace {

double fraction(int k0, int k1, double k) {
  if (k0 == k1) throw std::invalid_argument("interpolation: k0 and k1 are the same frame");
  return (k - k0) / static_cast<double>(k1 - k0);
}

}  // namespace

// (1 - s) a + s b rather than a + s (b - a): exact at both ends.
FeatureFrame lerp_features(const FeatureFrame& a, const FeatureFrame& b, double s) {
  if (s == 0.0) return a;
  if (s == 1.0) return b;
  return (1.0 - s) * a + s * b;
}

Positions lerp_positions(const Positions& a, const Positions& b, double s) {
  if (s == 0.0) return a;
  if (s == 1.0) return b;
  return (1.0 - s) * a + s * b;
}

FeatureFrame feature_space_frame(const SequenceFeatures& features, int k0, int k1, double k) {
  const int n = static_cast<int>(features.frames.size());
  if (k0 < 0 || k1 < 0 || k0 >= n || k1 >= n) throw std::out_of_range("interpolation: frame index");
  return lerp_features(features.frames[k0], features.frames[k1], fraction(k0, k1, k));
}

Positions feature_space_positions(const SequenceFeatures& features, const Reconstructor& solver,
                                  int k0, int k1, double k) {
  return solver.solve(features.scale.denormalise(feature_space_frame(features, k0, k1, k)));
}

Positions vertex_space_positions(const std::vector<Positions>& frames, int k0, int k1, double k) {
  const int n = static_cast<int>(frames.size());
  if (k0 < 0 || k1 < 0 || k0 >= n || k1 >= n) throw std::out_of_range("interpolation: frame index");
  return lerp_positions(frames[k0], frames[k1], fraction(k0, k1, k));
}

}  // namespace animrt::seqnet
