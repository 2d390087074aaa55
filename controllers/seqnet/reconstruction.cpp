#include "animrt/controllers/seqnet/reconstruction.hpp"

#include <Eigen/Sparse>
#include <algorithm>
#include <stdexcept>

#include "animrt/controllers/seqnet/placement.hpp"

namespace animrt::seqnet {

struct Reconstructor::Factor {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  // b = B t per coordinate row t of the gradients (3 V entries), and the
  // factor of B B^T for the minimal-norm correction.
  Eigen::SparseMatrix<double> b;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> bbt;
  bool bbt_ok = false;
};

Reconstructor::Reconstructor(const Positions& rest, const Triangles& triangles)
    : rest_(rest),
      ring_(build_neighbourhood(rest, triangles)),
      factor_(std::make_unique<Factor>()) {
  const int v = ring_.vertex_count;
  free_index_.assign(static_cast<std::size_t>(v), 0);
  std::vector<char> piece_pinned(static_cast<std::size_t>(ring_.piece_count), 0);
  int free = 0;
  for (int i = 0; i < v; ++i) {
    if (!piece_pinned[ring_.piece[i]]) {
      piece_pinned[ring_.piece[i]] = 1;
      free_index_[i] = -1;
    } else {
      free_index_[i] = free++;
    }
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < v; ++i) {
    const int r = free_index_[i];
    if (r < 0) continue;
    double diagonal = 0.0;
    for (int k = ring_.offsets[i]; k < ring_.offsets[i + 1]; ++k) {
      diagonal += ring_.weights[k];
      const int c = free_index_[ring_.neighbours[k]];
      if (c >= 0) entries.emplace_back(r, c, -ring_.weights[k]);
    }
    entries.emplace_back(r, r, diagonal);
  }
  std::vector<Eigen::Triplet<double>> b_entries;
  for (int i = 0; i < v; ++i) {
    const int r = free_index_[i];
    if (r < 0) continue;
    for (int k = ring_.offsets[i]; k < ring_.offsets[i + 1]; ++k) {
      const int j = ring_.neighbours[k];
      const Eigen::Vector3d d = 0.5 * ring_.weights[k] * (rest_.col(i) - rest_.col(j));
      for (int c = 0; c < 3; ++c) {
        b_entries.emplace_back(r, 3 * i + c, d[c]);
        b_entries.emplace_back(r, 3 * j + c, d[c]);
      }
    }
  }
  factor_->b.resize(free, 3 * v);
  factor_->b.setFromTriplets(b_entries.begin(), b_entries.end());
  if (free > 0) {
    Eigen::SparseMatrix<double> bbt =
        factor_->b * Eigen::SparseMatrix<double>(factor_->b.transpose());
    double trace = 0.0;
    for (int k = 0; k < free; ++k) trace += bbt.coeff(k, k);
    // A whisker of ridge keeps the factor defined if B loses rank.
    for (int k = 0; k < free; ++k) bbt.coeffRef(k, k) += 1e-12 * trace / free;
    factor_->bbt.compute(bbt);
    factor_->bbt_ok = factor_->bbt.info() == Eigen::Success;
  }
  Eigen::SparseMatrix<double> laplacian(free, free);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  if (free > 0) {
    factor_->ldlt.compute(laplacian);
    if (factor_->ldlt.info() != Eigen::Success) {
      throw std::runtime_error("Reconstructor: the Laplacian could not be factorised");
    }
  }
}

Reconstructor::~Reconstructor() = default;

Positions Reconstructor::solve(const FeatureFrame& raw) const {
  std::vector<Eigen::Matrix3d> gradients(static_cast<std::size_t>(raw.cols()));
  for (int i = 0; i < static_cast<int>(raw.cols()); ++i) gradients[i] = gradient_of(raw, i);
  return solve_gradients(gradients);
}

Positions Reconstructor::solve_gradients(const std::vector<Eigen::Matrix3d>& t) const {
  const int v = ring_.vertex_count;
  if (static_cast<int>(t.size()) != v) throw std::invalid_argument("Reconstructor: vertex count");
  int free = 0;
  for (int f : free_index_) free += f >= 0 ? 1 : 0;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(free, 3);
  for (int i = 0; i < v; ++i) {
    const int r = free_index_[i];
    if (r < 0) continue;
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (int k = ring_.offsets[i]; k < ring_.offsets[i + 1]; ++k) {
      const int j = ring_.neighbours[k];
      const double w = ring_.weights[k];
      b += 0.5 * w * (t[i] + t[j]) * (rest_.col(i) - rest_.col(j));
      if (free_index_[j] < 0) b += w * rest_.col(j);  // pinned neighbour moves to the right side
    }
    rhs.row(r) = b.transpose();
  }
  Positions out(3, v);
  const Eigen::MatrixXd solved = free > 0 ? Eigen::MatrixXd(factor_->ldlt.solve(rhs)) : rhs;
  for (int i = 0; i < v; ++i) {
    out.col(i) = free_index_[i] < 0 ? Eigen::Vector3d(rest_.col(i))
                                    : Eigen::Vector3d(solved.row(free_index_[i]).transpose());
  }
  return out;
}

std::vector<Eigen::Matrix3d> Reconstructor::exact_gradients(
    const std::vector<Eigen::Matrix3d>& fitted, const Positions& frame) const {
  std::vector<Eigen::Matrix3d> out = fitted;
  if (!factor_->bbt_ok) return out;
  const int v = ring_.vertex_count;
  const Eigen::Index free = factor_->b.rows();
  for (int x = 0; x < 3; ++x) {
    Eigen::VectorXd t(3 * v);
    for (int i = 0; i < v; ++i) t.segment<3>(3 * i) = fitted[i].row(x).transpose();
    Eigen::VectorXd target(free);
    for (int i = 0; i < v; ++i) {
      const int r = free_index_[i];
      if (r < 0) continue;
      double sum = 0.0;
      for (int k = ring_.offsets[i]; k < ring_.offsets[i + 1]; ++k) {
        sum += ring_.weights[k] * (frame(x, i) - frame(x, ring_.neighbours[k]));
      }
      target[r] = sum;
    }
    const Eigen::VectorXd residual = target - factor_->b * t;
    const Eigen::VectorXd y = factor_->bbt.solve(residual);
    const Eigen::VectorXd change = factor_->b.transpose() * y;
    for (int i = 0; i < v; ++i) out[i].row(x) += change.segment<3>(3 * i).transpose();
  }
  return out;
}

std::vector<Positions> reconstruct_all(const SequenceFeatures& features) {
  const Reconstructor solver(features.rest, features.triangles);
  std::vector<Positions> out;
  for (int f = 0; f < static_cast<int>(features.frames.size()); ++f) {
    out.push_back(reconstruct_frame(solver, features, f));
  }
  return out;
}

Positions reconstruct_frame(const Reconstructor& solver, const SequenceFeatures& features,
                            int frame) {
  Positions p = solver.solve(features.raw(frame));
  if (!features.placement.empty()) {
    place(solver.neighbourhood(), p, features.placement[static_cast<std::size_t>(frame)]);
  }
  return p;
}

Eigen::Matrix3Xd piece_offsets(const Neighbourhood& ring, const Positions& placed,
                               const Positions& frame) {
  Eigen::Matrix3Xd shift = Eigen::Matrix3Xd::Zero(3, ring.piece_count);
  std::vector<int> size(static_cast<std::size_t>(ring.piece_count), 0);
  for (int i = 0; i < ring.vertex_count; ++i) {
    shift.col(ring.piece[i]) += placed.col(i) - frame.col(i);
    ++size[ring.piece[i]];
  }
  for (int p = 0; p < ring.piece_count; ++p) shift.col(p) /= std::max(1, size[p]);
  return shift;
}

void move_pieces(const Neighbourhood& ring, Positions& frame, const Eigen::Matrix3Xd& offsets) {
  for (int i = 0; i < ring.vertex_count; ++i) frame.col(i) += offsets.col(ring.piece[i]);
}

FrameError error_up_to_translation(const Positions& expected, const Positions& got,
                                   const Neighbourhood& ring) {
  Positions moved = got;
  move_pieces(ring, moved, piece_offsets(ring, expected, got));
  const double diagonal = (expected.rowwise().maxCoeff() - expected.rowwise().minCoeff()).norm();
  FrameError out;
  for (int i = 0; i < ring.vertex_count; ++i) {
    const double d = (moved.col(i) - expected.col(i)).norm() / diagonal;
    out.mean += d;
    out.max = std::max(out.max, d);
  }
  out.mean /= std::max(1, ring.vertex_count);
  return out;
}

}  // namespace animrt::seqnet
