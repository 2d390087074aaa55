// The placement nodes of a feature set: the body's velocity per frame, and
// a held piece's offset from its anchor in the anchor's rotated frame,
// which stays constant while the whole figure turns and walks.

#include "animrt/controllers/seqnet/placement_nodes.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "animrt/learn/seqnet/shapes.hpp"

namespace animrt::seqnet {
namespace {

// A bar (the body) and a small sphere beside its top (the held piece),
// turning about x by 0.2 rad and walking 0.1 along y per frame.
MeshSequence turning_figure(int frames) {
  MeshSequence s = make_bar(4, 6, 4.0);
  const MeshSequence ball = make_icosphere(0);
  const int v = s.vertex_count();
  Positions rest(3, v + ball.vertex_count());
  rest.leftCols(v) = s.frames.front();
  rest.rightCols(ball.vertex_count()) =
      (0.3 * ball.frames.front()).colwise() + Eigen::Vector3d(1.6, 0.0, 3.5);
  for (auto t : ball.triangles) s.triangles.push_back({t[0] + v, t[1] + v, t[2] + v});
  s.frames.clear();
  for (int f = 0; f < frames; ++f) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.2 * f, Eigen::Vector3d::UnitX()).toRotationMatrix();
    s.frames.push_back((r * rest).colwise() + Eigen::Vector3d(0.0, 0.1 * f, 0.0));
  }
  return s;
}

TEST(SeqPlacementNodes, TrackCarriesTheWalkAndAConstantHeldPiece) {
  const MeshSequence s = turning_figure(6);
  const SequenceFeatures f = compute_features(s);
  const std::vector<Eigen::VectorXd> track = placement_track(f);
  ASSERT_EQ(track.size(), 6U);
  const Neighbourhood ring = build_neighbourhood(f.rest, f.triangles);
  const PlacementLayout layout = placement_layout(ring, f.rest);
  ASSERT_EQ(layout.nodes, 1);
  ASSERT_EQ(layout.body, 0);
  const int anchor = layout.anchor[1];
  ASSERT_GE(anchor, 0);
  const Eigen::Vector3d held = f.rest.rightCols(12).rowwise().mean() - f.rest.col(anchor);
  for (std::size_t k = 0; k < track.size(); ++k) {
    ASSERT_EQ(track[k].size(), 9);
    // The body's centroid turns about its own x axis: the turn adds
    // nothing to its move, the walk 0.1 per frame (the first frame takes
    // the second's).
    const Eigen::Vector3d body0 = s.frames[0].leftCols(26).rowwise().mean();
    const Eigen::Matrix3d r0 =
        Eigen::AngleAxisd(0.2 * std::max<double>(1, k), Eigen::Vector3d::UnitX())
            .toRotationMatrix();
    const Eigen::Matrix3d r1 =
        Eigen::AngleAxisd(0.2 * (std::max<double>(1, k) - 1), Eigen::Vector3d::UnitX())
            .toRotationMatrix();
    const Eigen::Vector3d want = (r0 - r1) * body0 + Eigen::Vector3d(0.0, 0.1, 0.0);
    EXPECT_LT((track[k].head<3>() - want).norm(), 1e-9) << k;
    EXPECT_LT((track[k].segment<3>(3) - held).norm(), 1e-6) << k;
    EXPECT_EQ(track[k].tail<3>().norm(), 0.0) << k;
  }
}

TEST(SeqPlacementNodes, PlacingByTheValuesPutsEveryPieceBack) {
  const MeshSequence s = turning_figure(4);
  const SequenceFeatures f = compute_features(s);
  const std::vector<Eigen::VectorXd> track = placement_track(f);
  const Neighbourhood ring = build_neighbourhood(f.rest, f.triangles);
  const PlacementLayout layout = placement_layout(ring, f.rest);
  const Positions& truth = s.frames[3];
  // Both pieces moved apart, then placed again.
  Positions p = truth;
  p.leftCols(26).colwise() += Eigen::Vector3d(5.0, -1.0, 2.0);
  p.rightCols(12).colwise() += Eigen::Vector3d(-3.0, 4.0, 0.5);
  place_by_values(layout, ring, p, f.raw(3), track[3], body_centroid(layout, ring, truth));
  EXPECT_LT((p - truth).colwise().norm().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace animrt::seqnet
