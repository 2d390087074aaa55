#pragma once
// Linear interpolation and extrapolation between two frames k0 and k1, in
// feature space (then reconstructed) and in vertex space: the yardsticks a
// learned sequence model has to beat. Frame k maps to s = (k - k0) / (k1 - k0);
// s outside [0, 1] extrapolates; s = 0 and s = 1 give the endpoints exactly.

#include <vector>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"

namespace animrt::seqnet {

FeatureFrame lerp_features(const FeatureFrame& a, const FeatureFrame& b, double s);
Positions lerp_positions(const Positions& a, const Positions& b, double s);

// Normalised features of frame k from frames k0 and k1 of `features`.
FeatureFrame feature_space_frame(const SequenceFeatures& features, int k0, int k1, double k);
// Positions of frame k from feature-space interpolation, reconstructed.
Positions feature_space_positions(const SequenceFeatures& features, const Reconstructor& solver,
                                  int k0, int k1, double k);
// Positions of frame k from vertex-space interpolation of frames k0 and k1.
Positions vertex_space_positions(const std::vector<Positions>& frames, int k0, int k1, double k);

}  // namespace animrt::seqnet
