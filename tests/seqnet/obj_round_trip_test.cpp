// A generated sequence written as a folder of OBJ files (by a small local
// writer), read back, turned into features, stored, loaded and rebuilt.

#include <gtest/gtest.h>

#include <numbers>

#include "animrt/controllers/seqnet/feature_file.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "seq_test_util.hpp"

namespace animrt::seqnet {
namespace {

TEST(ObjRoundTrip, FolderToFeatureFileAndBack) {
  const MeshSequence bar = make_twisting_bar(12, 10, 6.0, 1.25 * std::numbers::pi, 6);
  const std::string dir = seqtest::temp_path("bar_frames");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (int f = 0; f < bar.frame_count(); ++f) {
    seqtest::write_obj_frame(dir + "/frame_" + std::to_string(f) + ".obj", bar, f);
  }
  const MeshSequence read = read_mesh_sequence(dir);
  ASSERT_EQ(read.frame_count(), bar.frame_count());
  EXPECT_EQ(read.triangles, bar.triangles);
  const std::string file = seqtest::temp_path("bar.bin");
  write_feature_file(file, compute_features(read));
  const SequenceFeatures loaded = read_feature_file(file);
  const std::vector<Positions> rebuilt = reconstruct_all(loaded);
  const Reconstructor solver(loaded.rest, loaded.triangles);
  ASSERT_EQ(rebuilt.size(), 6u);
  for (int f = 0; f < 6; ++f) {
    const FrameError e = error_up_to_translation(bar.frames[f], rebuilt[f], solver.neighbourhood());
    EXPECT_LT(e.max, 1e-8) << "frame " << f;
  }
  // The twist really moved the bar: frame 5 is far from frame 0.
  const FrameError moved =
      error_up_to_translation(bar.frames[5], bar.frames[0], solver.neighbourhood());
  EXPECT_GT(moved.max, 0.1);
}

}  // namespace
}  // namespace animrt::seqnet
