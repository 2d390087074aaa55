#pragma once
// Where a frame is, in numbers the sequence network can carry beside the
// deformation features: nodes of 9 numbers appended to the 9 V features.
// The body (the piece with the most vertices) moves by its centroid's
// velocity, so a walk goes forward wherever it starts; every other piece
// sits at its centroid relative to an anchor vertex of the body, in that
// vertex's rotated frame, so a rigid piece held by the body (a sword in a
// hand) is a constant the network only has to keep.

#include <Eigen/Core>
#include <vector>

#include "animrt/controllers/seqnet/deformation.hpp"
#include "animrt/controllers/seqnet/features.hpp"

namespace animrt::seqnet {

struct PlacementLayout {
  int body = 0;  // the piece with the most vertices (the first on a tie)
  std::vector<int>
      anchor;     // per piece: the body vertex nearest its template centroid; -1 for the body
  int nodes = 0;  // 9-number nodes: ceil(3 pieces / 9)
  int values() const { return 9 * nodes; }
};
PlacementLayout placement_layout(const Neighbourhood& ring, const Positions& rest);

Eigen::Vector3d body_centroid(const PlacementLayout& layout, const Neighbourhood& ring,
                              const Positions& frame);

// 9 nodes numbers of one frame: the body's velocity (its centroid's move
// per frame), then for every other piece in order R_a^T (c_p - x_a), c_p
// its centroid, x_a its anchor and R_a the anchor's rotation in `raw`
// (the frame's raw features); zeros after.
Eigen::VectorXd placement_values(const PlacementLayout& layout, const Neighbourhood& ring,
                                 const Positions& frame, const FeatureFrame& raw,
                                 const Eigen::Vector3d& velocity);

// Moves the pieces of a reconstructed frame (each piece at any translation)
// so that the body's centroid is `centroid` and every other piece sits
// where `values` put it relative to its anchor.
void place_by_values(const PlacementLayout& layout, const Neighbourhood& ring, Positions& frame,
                     const FeatureFrame& raw, const Eigen::VectorXd& values,
                     const Eigen::Vector3d& centroid);

// The placement values of every frame of a feature set that carries its
// placement (absolute frames): a clip's first frame takes its second
// frame's velocity (0 for a clip of one frame). Empty without placement.
std::vector<Eigen::VectorXd> placement_track(const SequenceFeatures& features);

}  // namespace animrt::seqnet
