#pragma once
// Deformation features of a mesh sequence (docs/seqnet.md): per vertex and
// frame the deformation gradient against the template (frame 0), split into
// rotation R and stretch S; 9 numbers per vertex, the rotation as an
// axis-angle vector kept consistent across the mesh and across frames, then
// each of the 9 V numbers mapped linearly to [-0.95, 0.95].

#include <Eigen/Core>
#include <vector>

#include "animrt/controllers/seqnet/deformation.hpp"
#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet {

constexpr int kFeatureDims = 9;  // rx ry rz s00 s01 s02 s11 s12 s22
// One column per vertex.
using FeatureFrame = Eigen::Matrix<double, kFeatureDims, Eigen::Dynamic>;

// The features of one frame from its deformation gradients. Every rotation
// vector is chosen among its equivalents closest to a reference: for the
// first vertex of each piece its own vector in `previous`; for a vertex
// reached from a neighbour p in a breadth-first walk, its vector in
// `previous` moved by p's change since `previous`.
FeatureFrame features_from_gradients(const std::vector<Eigen::Matrix3d>& gradients,
                                     const Neighbourhood& ring, const FeatureFrame& previous);
// The gradient exp(r) * S a feature column stands for.
Eigen::Matrix3d gradient_of(const FeatureFrame& features, int vertex);

// Per-dimension linear map of raw features to [-0.95, 0.95]; a dimension
// that never changes maps to 0 and back to its value.
struct FeatureScale {
  FeatureFrame low;
  FeatureFrame high;

  static FeatureScale fit(const std::vector<FeatureFrame>& raw);
  FeatureFrame normalise(const FeatureFrame& raw) const;
  FeatureFrame denormalise(const FeatureFrame& normalised) const;
};

struct SequenceFeatures {
  Positions rest;  // the template: frame 0 of the sequence
  Triangles triangles;
  std::vector<Clip> clips;  // frame ranges within `frames`
  FeatureScale scale;
  std::vector<FeatureFrame> frames;  // normalised
  // Per frame, the root and every piece's offset from it (placement.hpp);
  // empty when read from a version-1 feature file, which did not store it.
  std::vector<Eigen::Matrix3Xd> placement;

  int vertex_count() const { return static_cast<int>(rest.cols()); }
  FeatureFrame raw(int frame) const {
    return scale.denormalise(frames[static_cast<std::size_t>(frame)]);
  }
};

// Features of frames first .. first + count - 1 against frame 0 (the whole
// sequence when count is 0), clips that lie inside that range kept.
// Rotations follow frame to frame within a clip; a clip's first frame is
// referred to the template. With
// exact_round_trip the fitted gradients get the minimal correction that
// makes reconstruction give the frame back (Reconstructor::exact_gradients);
// without it they are the plain per-vertex fits of the paper's Eq. 1.
SequenceFeatures compute_features(const MeshSequence& sequence, int first = 0, int count = 0,
                                  bool exact_round_trip = true);

}  // namespace animrt::seqnet
