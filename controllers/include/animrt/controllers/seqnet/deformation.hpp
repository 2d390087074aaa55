#pragma once
// Per-vertex deformation gradients of a mesh frame against a template frame
// over each vertex's 1-ring, weighted by cotangent weights, and the rotation
// tools the deformation features are built from (docs/seqnet.md).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"

namespace animrt::seqnet {

using Triangles = std::vector<std::array<int, 3>>;

// Cotangent weight of every edge (i < j): half the sum of the cotangents of
// the angles opposite it (one angle on a boundary edge), negative values
// clamped to 0.
struct EdgeWeights {
  std::vector<std::array<int, 2>> edges;
  std::vector<double> weights;
};
EdgeWeights cotangent_weights(const Positions& rest, const Triangles& triangles);

// The template's 1-ring structure, built once per connectivity.
struct Neighbourhood {
  int vertex_count = 0;
  // Compressed rows: the neighbours of vertex i are neighbours[offsets[i] ..
  // offsets[i+1]) with the weights used in the fits: cotangent weights with
  // a floor of 1e-3 of their mean, so that a clamped edge still ties its
  // vertices together.
  std::vector<int> offsets;
  std::vector<int> neighbours;
  std::vector<double> weights;
  std::vector<int> piece;  // connected piece of every vertex
  int piece_count = 0;
  std::vector<double> ring_area;  // template area of the triangles around each vertex
};
Neighbourhood build_neighbourhood(const Positions& rest, const Triangles& triangles);

// Area-weighted vertex normals (unit; zero where undefined).
Positions vertex_normals(const Positions& points, const Triangles& triangles);
// Area of the triangles around each vertex.
std::vector<double> ring_areas(const Positions& points, const Triangles& triangles);

// D_i = argmin sum_j c_ij |(p_i - p_j) - D (q_i - q_j)|^2 for frame p against
// template q. Where the 1-ring is (nearly) flat the 3x3 system is singular
// in the normal direction; there the template normal, mapped to the frame's
// normal scaled by the change of ring area, is added as one more weighted
// direction, which leaves well-conditioned rings untouched.
std::vector<Eigen::Matrix3d> deformation_gradients(const Neighbourhood& ring,
                                                   const Triangles& triangles,
                                                   const Positions& rest, const Positions& frame);

// T = R S with R a rotation (det +1) and S symmetric.
struct Polar {
  Eigen::Matrix3d rotation;
  Eigen::Matrix3d stretch;
};
Polar polar_decomposition(const Eigen::Matrix3d& t);

// Axis-angle vector (angle in [0, pi]) of a rotation and its inverse.
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& r);
Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& v);
// Among the vectors of the same rotation as v ((theta + 2 pi k) * axis for
// every integer k, which includes the flipped axis with 2 pi - theta), the
// one closest to `reference`.
Eigen::Vector3d closest_equivalent(const Eigen::Vector3d& v, const Eigen::Vector3d& reference);

}  // namespace animrt::seqnet
