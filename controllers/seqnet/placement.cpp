#include "animrt/controllers/seqnet/placement.hpp"

#include <algorithm>
#include <stdexcept>

namespace animrt::seqnet {

Placement placement_of(const Neighbourhood& ring, const Positions& frame) {
  if (frame.cols() != ring.vertex_count) throw std::invalid_argument("placement_of: vertex count");
  Placement out = Placement::Zero(3, 1 + ring.piece_count);
  std::vector<int> size(static_cast<std::size_t>(ring.piece_count), 0);
  for (int i = 0; i < ring.vertex_count; ++i) {
    out.col(1 + ring.piece[i]) += frame.col(i);
    ++size[ring.piece[i]];
  }
  out.col(0) = frame.rowwise().mean();
  for (int p = 0; p < ring.piece_count; ++p) {
    out.col(1 + p) = out.col(1 + p) / std::max(1, size[p]) - out.col(0);
  }
  return out;
}

void place(const Neighbourhood& ring, Positions& frame, const Placement& placement) {
  if (placement.cols() != 1 + ring.piece_count) throw std::invalid_argument("place: piece count");
  const Placement now = placement_of(ring, frame);
  for (int i = 0; i < ring.vertex_count; ++i) {
    const int p = 1 + ring.piece[i];
    frame.col(i) += placement.col(0) + placement.col(p) - now.col(0) - now.col(p);
  }
}

AbsoluteError absolute_error(const Positions& expected, const Positions& got) {
  const double diagonal = (expected.rowwise().maxCoeff() - expected.rowwise().minCoeff()).norm();
  AbsoluteError out;
  for (Eigen::Index i = 0; i < expected.cols(); ++i) {
    const double d = (got.col(i) - expected.col(i)).norm() / diagonal;
    out.mean += d;
    out.max = std::max(out.max, d);
  }
  out.mean /= std::max<Eigen::Index>(1, expected.cols());
  return out;
}

}  // namespace animrt::seqnet
