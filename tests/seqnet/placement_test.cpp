// Absolute placement: the feature file carries every piece's translation and
// the root trajectory, so reconstruction gives every frame back where it
// was, on a real multi-piece game model and on a bar that walks away while
// a separate rigid piece swings around it; older files are still read.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "seq_test_util.hpp"

namespace animrt::seqnet {
namespace {

const char* kFaerie = "/usr/share/doc/libirrlicht-dev/media/faerie.md2.gz";

// The largest vertex distance of `got` from `expected`, with nothing
// aligned, as a fraction of expected's bounding-box diagonal.
double worst_distance(const Positions& expected, const Positions& got) {
  const double diagonal = (expected.rowwise().maxCoeff() - expected.rowwise().minCoeff()).norm();
  return (got - expected).colwise().norm().maxCoeff() / diagonal;
}

void expect_absolute_round_trip(const MeshSequence& s, const std::string& name) {
  const std::string file = seqtest::temp_path(name + ".features");
  write_feature_file(file, compute_features(s));
  const std::vector<Positions> got = reconstruct_all(read_feature_file(file));
  ASSERT_EQ(got.size(), s.frames.size());
  for (std::size_t f = 0; f < got.size(); ++f) {
    EXPECT_LT(worst_distance(s.frames[f], got[f]), 1e-6) << name << " frame " << f;
  }
}

// The bar walks along x by 0.1 per frame and twists; a small rigid block,
// a piece of its own, circles the bar's top at a fixed distance.
MeshSequence walking_bar_with_a_sword(int frames) {
  MeshSequence s = make_twisting_bar(4, 6, 4.0, 1.5, frames);
  const MeshSequence block = make_bar(2, 4, 0.5);
  const int v = s.vertex_count();
  for (const auto& t : block.triangles) s.triangles.push_back({t[0] + v, t[1] + v, t[2] + v});
  for (int f = 0; f < frames; ++f) {
    const double a = 1.5 * f / (frames - 1);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Positions both(3, v + block.vertex_count());
    both.leftCols(v) = s.frames[static_cast<std::size_t>(f)];
    both.rightCols(block.vertex_count()) =
        (turn * ((0.3 * block.frames[0]).colwise() + Eigen::Vector3d(2.0, 0.0, 3.0))).eval();
    both.row(0).array() += 0.1 * f;
    s.frames[static_cast<std::size_t>(f)] = both;
  }
  return s;
}

TEST(SeqPlacement, FaerieFramesComeBackInAbsoluteCoordinates) {
  if (!std::filesystem::exists(kFaerie)) {
    FAIL() << kFaerie << " is missing: install the Debian package libirrlicht-doc";
  }
  const MeshSequence all = read_mesh_sequence(kFaerie);
  // Frame 0 and every clip's last frame, where pieces are furthest from
  // their template place (crdeath5 among them).
  MeshSequence s;
  s.triangles = all.triangles;
  s.frames.push_back(all.frames[0]);
  for (const Clip& c : all.clips) s.frames.push_back(all.frames[c.first + c.count - 1]);
  const Reconstructor solver(s.frames[0], s.triangles);
  ASSERT_GE(solver.neighbourhood().piece_count, 13);
  expect_absolute_round_trip(s, "faerie");
}

TEST(SeqPlacement, AWalkReconstructsWalkingAndTheSwordStaysInPlace) {
  const MeshSequence s = walking_bar_with_a_sword(12);
  expect_absolute_round_trip(s, "walking_bar");
  const std::vector<Positions> got = reconstruct_all(compute_features(s));
  // The bar's own vertices moved 1.1 along x.
  const Eigen::Index bar = make_bar(4, 6, 4.0).vertex_count();
  EXPECT_NEAR(got.back().leftCols(bar).row(0).mean() - got.front().leftCols(bar).row(0).mean(),
              1.1, 1e-6);
}

TEST(SeqPlacement, VersionOneFilesAreReadWithoutPlacement) {
  SequenceFeatures f = compute_features(walking_bar_with_a_sword(4));
  f.placement.clear();  // written in the version-1 layout
  const std::string file = seqtest::temp_path("version1.features");
  write_feature_file(file, f);
  const SequenceFeatures back = read_feature_file(file);
  EXPECT_TRUE(back.placement.empty());
  ASSERT_EQ(back.frames.size(), 4U);
  EXPECT_TRUE(back.frames[3].isApprox(f.frames[3], 0.0));
}

TEST(SeqPlacement, APlacementOfAnotherPieceCountIsRefusedByName) {
  SequenceFeatures f = compute_features(walking_bar_with_a_sword(3));
  for (auto& p : f.placement) p.conservativeResize(3, p.cols() + 1);
  const std::string file = seqtest::temp_path("pieces.features");
  write_feature_file(file, f);
  try {
    read_feature_file(file);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file + ": header: placement of 3 pieces, the triangles "
                                                "make 2"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace animrt::seqnet
