#pragma once
// Where a frame is, which its deformation features cannot say: the root (the
// mean of all vertices) and every connected piece's centroid relative to
// the root. Reconstruction from the features alone leaves each piece at an
// arbitrary translation; moving every piece so its centroid is the root
// plus its offset puts the frame back in absolute coordinates.

#include <Eigen/Core>

#include "animrt/controllers/seqnet/deformation.hpp"

namespace animrt::seqnet {

// 3 x (1 + pieces): column 0 the root, column 1 + p piece p's centroid
// minus the root.
using Placement = Eigen::Matrix3Xd;

Placement placement_of(const Neighbourhood& ring, const Positions& frame);
// Moves every piece of `frame` so that placement_of(frame) is `placement`.
void place(const Neighbourhood& ring, Positions& frame, const Placement& placement);

// Vertex distances between two frames with nothing aligned, as fractions of
// expected's bounding-box diagonal.
struct AbsoluteError {
  double mean = 0.0;
  double max = 0.0;
};
AbsoluteError absolute_error(const Positions& expected, const Positions& got);

}  // namespace animrt::seqnet
