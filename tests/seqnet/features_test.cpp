// Deformation features: cotangent weights, gradients, polar split, rotation
// consistency, reconstruction and interpolation.

#include "animrt/controllers/seqnet/features.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <numbers>

#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/learn/seqnet/interpolation.hpp"
#include "animrt/learn/seqnet/shapes.hpp"

namespace animrt::seqnet {
namespace {

constexpr double kPi = std::numbers::pi;

double weight_of(const EdgeWeights& w, int a, int b) {
  for (std::size_t e = 0; e < w.edges.size(); ++e) {
    if (w.edges[e] == std::array<int, 2>{a, b}) return w.weights[e];
  }
  ADD_FAILURE() << "no edge " << a << "-" << b;
  return -1.0;
}

TEST(CotangentWeights, HandComputedWithObtuseAngleClamped) {
  // Triangle 0,1,2 is obtuse at 2 (cot -3/4); triangle 0,3,1 sits below.
  Positions p(3, 4);
  p << 0, 2, 1, 1,    //
      0, 0, 0.5, -3,  //
      0, 0, 0, 0;
  const Triangles t = {{0, 1, 2}, {0, 3, 1}};
  const EdgeWeights w = cotangent_weights(p, t);
  ASSERT_EQ(w.edges.size(), 5u);
  EXPECT_NEAR(weight_of(w, 1, 2), 1.0, 1e-12);         // cot 2 at vertex 0, halved
  EXPECT_NEAR(weight_of(w, 0, 2), 1.0, 1e-12);         // cot 2 at vertex 1
  EXPECT_NEAR(weight_of(w, 0, 1), 7.0 / 24.0, 1e-12);  // (-3/4 + 4/3) / 2
  EXPECT_NEAR(weight_of(w, 0, 3), 1.0 / 6.0, 1e-12);   // cot 1/3 at vertex 1
  EXPECT_NEAR(weight_of(w, 1, 3), 1.0 / 6.0, 1e-12);   // cot 1/3 at vertex 0
  // Alone, the obtuse triangle's edge 0-1 would be -3/8: clamped to 0.
  const EdgeWeights single = cotangent_weights(p, {{0, 1, 2}});
  EXPECT_EQ(weight_of(single, 0, 1), 0.0);
}

TEST(DeformationGradient, AffineMapIsRecoveredAtEveryVertex) {
  const MeshSequence sphere = make_icosphere(0);
  Eigen::Matrix3d m;
  m << 1.2, 0.3, 0.0, -0.1, 0.9, 0.2, 0.05, 0.0, 1.4;
  const Positions moved = (m * sphere.frames[0]).colwise() + Eigen::Vector3d(3, -1, 2);
  const Neighbourhood ring = build_neighbourhood(sphere.frames[0], sphere.triangles);
  const auto d = deformation_gradients(ring, sphere.triangles, sphere.frames[0], moved);
  ASSERT_EQ(d.size(), 12u);
  for (const auto& g : d) EXPECT_LT((g - m).norm(), 1e-10) << g;
  // The exact-round-trip correction leaves a consistent field alone.
  const Reconstructor solver(sphere.frames[0], sphere.triangles);
  for (const auto& g : solver.exact_gradients(d, moved)) EXPECT_LT((g - m).norm(), 1e-9);
}

TEST(DeformationGradient, FlatRingsStayInvertible) {
  // A flat 3 x 3 grid: every 1-ring is planar; rotated rigidly, the
  // gradient is that rotation.
  Positions p(3, 9);
  for (int i = 0; i < 9; ++i) p.col(i) << i % 3, i / 3, 0;
  Triangles t;
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 2; ++x) {
      const int a = 3 * y + x;
      t.push_back({a, a + 1, a + 4});
      t.push_back({a, a + 4, a + 3});
    }
  }
  const Eigen::Matrix3d r = rotation_exp(Eigen::Vector3d(0.3, -0.5, 0.8));
  const Neighbourhood ring = build_neighbourhood(p, t);
  for (const auto& g : deformation_gradients(ring, t, p, r * p)) {
    EXPECT_TRUE(g.allFinite());
    EXPECT_LT((g - r).norm(), 1e-9) << g;
  }
}

TEST(Polar, RotationTimesSymmetricWithPositiveDeterminant) {
  Eigen::Matrix3d t;
  t << 1.0, 0.4, -0.2, 0.1, 0.8, 0.3, -0.3, 0.2, 1.5;
  for (const Eigen::Matrix3d& m :
       {Eigen::Matrix3d(t), Eigen::Matrix3d(t * Eigen::Vector3d(1, 1, -1).asDiagonal())}) {
    const Polar p = polar_decomposition(m);
    EXPECT_LT((p.rotation * p.rotation.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(p.rotation.determinant(), 1.0, 1e-12);
    EXPECT_LT((p.stretch - p.stretch.transpose()).norm(), 1e-12);
    EXPECT_LT((p.rotation * p.stretch - m).norm(), 1e-12);
  }
  // A pure rotation has S = I.
  const Eigen::Matrix3d r = rotation_exp(Eigen::Vector3d(1.0, 2.0, -0.5));
  EXPECT_LT((polar_decomposition(r).stretch - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Rotation, ClosestEquivalentAddsTurnsOrFlipsTheAxis) {
  const Eigen::Vector3d z(0, 0, 1);
  EXPECT_LT((closest_equivalent(0.5 * z, 2 * kPi * z) - (2 * kPi + 0.5) * z).norm(), 1e-12);
  // 3 rad about z is also 3 - 2 pi about z (= 2 pi - 3 about -z).
  EXPECT_LT((closest_equivalent(3.0 * z, -3.2 * z) - (3.0 - 2 * kPi) * z).norm(), 1e-12);
  EXPECT_LT((closest_equivalent(3.0 * z, 2.9 * z) - 3.0 * z).norm(), 1e-12);
  EXPECT_LT((rotation_exp(closest_equivalent(3.0 * z, -3.2 * z)) - rotation_exp(3.0 * z)).norm(),
            1e-12);
  EXPECT_LT((rotation_log(rotation_exp(Eigen::Vector3d(0.2, -0.4, 1.1))) -
             Eigen::Vector3d(0.2, -0.4, 1.1))
                .norm(),
            1e-12);
}

// The largest distance of the top ring's rotation vectors from `expected`
// (the top quarter of the bar turns rigidly).
double top_rotation_error(const SequenceFeatures& f, int frame, int rings, int around,
                          const Eigen::Vector3d& expected) {
  const FeatureFrame raw = f.raw(frame);
  double worst = 0.0;
  for (int a = 0; a < around; ++a) {
    worst = std::max(worst, (raw.block<3, 1>(0, (rings - 1) * around + a) - expected).norm());
  }
  return worst;
}

TEST(Rotation, ConsistentThroughAFullTwistAcrossFrames) {
  const int rings = 31, around = 12, frames = 25;
  const MeshSequence bar = make_twisting_bar(rings, around, 12.0, 2 * kPi, frames);
  // The plain fits: the round-trip correction spreads small changes over
  // the whole mesh, also onto the rigid top.
  const SequenceFeatures plain = compute_features(bar, 0, 0, false);
  const SequenceFeatures f = compute_features(bar);
  // Up to 345 degrees; at a whole turn the sheared middle cannot follow
  // (docs/seqnet.md) and the test stops short of it.
  for (int k = 0; k < frames - 1; ++k) {
    // About +z, growing with the twist past pi.
    const Eigen::Vector3d expected(0, 0, 2 * kPi * k / (frames - 1));
    EXPECT_LT(top_rotation_error(plain, k, rings, around, expected), 1e-6) << "frame " << k;
    // Corrected, near a whole turn the rotation is close to the identity
    // and its axis is ill-conditioned (docs/seqnet.md); up to 240 degrees
    // the correction keeps the top close.
    if (k <= 16) {
      EXPECT_LT(top_rotation_error(f, k, rings, around, expected), 0.1) << "frame " << k;
    }
  }
  // Round trip through the normalisation on every frame.
  const Reconstructor solver(f.rest, f.triangles);
  for (int k = 0; k < frames; ++k) {
    const FrameError e =
        error_up_to_translation(bar.frames[k], solver.solve(f.raw(k)), solver.neighbourhood());
    EXPECT_LT(e.max, 1e-6) << "frame " << k;
  }
}

TEST(Rotation, ConsistentAcrossTheMeshWithinOneFrame) {
  // Only the rest and the fully twisted frame: no frame-to-frame help, the
  // walk over the mesh alone must carry the angle up to 2 pi.
  const int rings = 31, around = 12;
  const MeshSequence bar = make_twisting_bar(rings, around, 12.0, 1.8 * kPi, 2);
  const SequenceFeatures f = compute_features(bar, 0, 0, false);
  EXPECT_LT(top_rotation_error(f, 1, rings, around, Eigen::Vector3d(0, 0, 1.8 * kPi)), 1e-6);
}

TEST(Interpolation, FeatureSpaceFollowsTheTwistVertexSpaceCollapses) {
  const int rings = 31, around = 12, frames = 13;
  const MeshSequence bar = make_twisting_bar(rings, around, 12.0, kPi * 1.5, frames);
  const SequenceFeatures f = compute_features(bar, 0, 0, false);
  const Reconstructor solver(f.rest, f.triangles);
  // Endpoints exact.
  EXPECT_EQ(feature_space_frame(f, 0, 12, 0.0), f.frames[0]);
  EXPECT_EQ(feature_space_frame(f, 0, 12, 12.0), f.frames[12]);
  EXPECT_EQ(vertex_space_positions(bar.frames, 0, 12, 12.0), bar.frames[12]);
  EXPECT_EQ(vertex_space_positions(bar.frames, 4, 8, 4.0), bar.frames[4]);
  // Half way through a 270-degree twist.
  const FrameError feature = error_up_to_translation(
      bar.frames[6], feature_space_positions(f, solver, 0, 12, 6.0), solver.neighbourhood());
  const FrameError vertex = error_up_to_translation(
      bar.frames[6], vertex_space_positions(bar.frames, 0, 12, 6.0), solver.neighbourhood());
  EXPECT_LT(feature.mean, 0.02);
  EXPECT_LT(feature.mean * 5, vertex.mean);
  EXPECT_GT(vertex.mean, 0.05);
  // Extrapolation from frames 4 and 6 to 8 continues the twist.
  const FrameError ahead = error_up_to_translation(
      bar.frames[8], feature_space_positions(f, solver, 4, 6, 8.0), solver.neighbourhood());
  EXPECT_LT(ahead.mean, 0.01);
}

TEST(Interpolation, VertexSpaceIsLinear) {
  std::vector<Positions> frames(3, Positions::Zero(3, 2));
  frames[1].setConstant(1.0);
  frames[2].setConstant(2.0);
  const Positions beyond = vertex_space_positions(frames, 0, 1, 2.0);
  EXPECT_LT((beyond - frames[2]).norm(), 1e-12);
  EXPECT_LT((vertex_space_positions(frames, 0, 2, 1.0) - frames[1]).norm(), 1e-12);
}

TEST(FeatureScale, MapsEachDimensionIntoRangeAndBack) {
  const MeshSequence bar = make_twisting_bar(5, 6, 2.0, kPi, 4);
  const SequenceFeatures f = compute_features(bar);
  for (const auto& frame : f.frames) {
    EXPECT_LE(frame.maxCoeff(), 0.95 + 1e-12);
    EXPECT_GE(frame.minCoeff(), -0.95 - 1e-12);
  }
  // Some dimension spans the whole range.
  EXPECT_NEAR(f.frames.back().maxCoeff(), 0.95, 1e-9);
  const FeatureFrame raw = f.raw(2);
  EXPECT_LT((f.scale.normalise(raw) - f.frames[2]).norm(), 1e-12);
}

}  // namespace
}  // namespace animrt::seqnet
