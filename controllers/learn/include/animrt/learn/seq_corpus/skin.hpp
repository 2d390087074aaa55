#pragma once
// A skinned mesh around a MuJoCo model: one closed, manifold triangle mesh
// made from the bodies' distance field (body_field.hpp) at a bind pose (a
// fine marching-tetrahedra surface, its largest component, decimated to
// the vertex count asked for), each
// vertex bound to the bodies nearest to it, posed by linear blend skinning
// with every body's world transform relative to the bind pose.

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

#include "animrt/controllers/seqnet/mesh_sequence.hpp"
#include "animrt/learn/seq_corpus/triangle_mesh.hpp"

namespace animrt::learn::seq_corpus {

// Bodies that move a vertex, at most.
constexpr int kInfluences = 3;

struct SkinOptions {
  int target_vertices = 1000;  // the grid step is chosen to come close
};

struct Skin {
  TriangleMesh rest;         // at the bind pose, world frame
  double grid_step_m = 0.0;  // of the fine surface it was decimated from
  // Per vertex: body ids and weights (summing to 1); unused slots have
  // weight 0 and body 0.
  std::vector<std::array<int, kInfluences>> bodies;
  std::vector<std::array<double, kInfluences>> weights;
  // Every body's bind-pose world transform, by body id.
  std::vector<Eigen::Vector3d> bind_pos;
  std::vector<Eigen::Matrix3d> bind_rot;
};

// The skin of the model posed as in `d` (after mj_forward or
// mj_kinematics). Throws std::runtime_error when the surface it finds is not
// one closed manifold (which would be a bug, not bad input).
Skin build_skin(const mjModel* m, const mjData* d, const SkinOptions& options);

// Vertex positions for the bodies' transforms in `d`, into `out` (resized).
void pose_skin(const Skin& skin, const mjData* d, seqnet::Positions& out);

// The body that moves vertex `v` most.
int dominant_body(const Skin& skin, int v);

}  // namespace animrt::learn::seq_corpus
