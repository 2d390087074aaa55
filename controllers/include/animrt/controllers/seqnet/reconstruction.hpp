#pragma once
// Vertex positions from deformation features: the sparse least-squares
// solve  min sum_i sum_j c_ij |(p_i - p_j) - T_i (q_i - q_j)|^2  against
// the template q, whose normal equations are a cotangent Laplacian system.
// It is factorised once per connectivity and solved per frame; the lowest
// vertex of every connected piece is pinned at its template position.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "animrt/controllers/seqnet/features.hpp"

namespace animrt::seqnet {

class Reconstructor {
 public:
  Reconstructor(const Positions& rest, const Triangles& triangles);
  ~Reconstructor();
  Reconstructor(const Reconstructor&) = delete;
  Reconstructor& operator=(const Reconstructor&) = delete;

  // From raw (denormalised) features or from gradients directly.
  Positions solve(const FeatureFrame& raw) const;
  Positions solve_gradients(const std::vector<Eigen::Matrix3d>& gradients) const;

  // The gradients nearest (least squares over all 9 V entries) to `fitted`
  // for which solve_gradients gives back `frame` exactly, up to a
  // translation per piece: the per-vertex fits of Eq. 1 disagree slightly
  // along shared edges, which on coarse game meshes costs several per cent
  // of the size in the round trip; this removes exactly that disagreement.
  std::vector<Eigen::Matrix3d> exact_gradients(const std::vector<Eigen::Matrix3d>& fitted,
                                               const Positions& frame) const;

  const Neighbourhood& neighbourhood() const { return ring_; }

 private:
  struct Factor;
  Positions rest_;
  Neighbourhood ring_;
  std::vector<int> free_index_;  // -1 for a pinned vertex
  std::unique_ptr<Factor> factor_;
};

// Every frame of a feature set back to positions: in absolute coordinates
// when the features carry their placement, else each piece pinned at its
// template vertex.
std::vector<Positions> reconstruct_all(const SequenceFeatures& features);
// Frame `frame` of a feature set so: `solver` of its template and triangles.
Positions reconstruct_frame(const Reconstructor& solver, const SequenceFeatures& features,
                            int frame);

// The mean offset of every connected piece of `placed` from the same piece
// of `frame` (3 x pieces), and `frame` with its pieces moved by such offsets:
// how reconstructed frames, which sit at the template's pinned vertices, are
// put where given frames are.
Eigen::Matrix3Xd piece_offsets(const Neighbourhood& ring, const Positions& placed,
                               const Positions& frame);
void move_pieces(const Neighbourhood& ring, Positions& frame, const Eigen::Matrix3Xd& offsets);

// Distance between two frames after moving every piece of `got` so that
// its centroid matches `expected`'s, as fractions of expected's bounding-box
// diagonal.
struct FrameError {
  double mean = 0.0;
  double max = 0.0;
};
FrameError error_up_to_translation(const Positions& expected, const Positions& got,
                                   const Neighbourhood& ring);

}  // namespace animrt::seqnet
