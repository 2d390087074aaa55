// The readers and the feature round trip on real game models from Debian
// packages: Irrlicht's sydney.md2.gz and OpenArena's sarge lower.md3.

#include <gtest/gtest.h>

#include "animrt/controllers/seqnet/features.hpp"
#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/controllers/seqnet/reconstruction.hpp"
#include "seq_test_util.hpp"

namespace animrt::seqnet {
namespace {

const Clip* find_clip(const MeshSequence& s, const std::string& name) {
  for (const auto& c : s.clips) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

// Frame 0 plus the first, middle and last frame of every clip.
MeshSequence sampled(const MeshSequence& s, std::vector<int>& picked) {
  MeshSequence out;
  out.triangles = s.triangles;
  picked = {0};
  for (const auto& c : s.clips) {
    for (int f : {c.first, c.first + c.count / 2, c.first + c.count - 1}) picked.push_back(f);
  }
  for (int f : picked) out.frames.push_back(s.frames[static_cast<std::size_t>(f)]);
  return out;
}

// Through the normalisation both ways; the plain per-vertex fits (Eq. 1)
// are checked against a looser bound: they are what the correction starts
// from and must already be close.
void expect_round_trip(const MeshSequence& s) {
  std::vector<int> picked;
  const MeshSequence sub = sampled(s, picked);
  const SequenceFeatures features = compute_features(sub);
  const Reconstructor solver(features.rest, features.triangles);
  for (std::size_t k = 0; k < picked.size(); ++k) {
    const Positions got = solver.solve(features.raw(static_cast<int>(k)));
    const FrameError e = error_up_to_translation(sub.frames[k], got, solver.neighbourhood());
    EXPECT_LT(e.mean, 0.002) << s.source << " frame " << picked[k];
    EXPECT_LT(e.max, 0.01) << s.source << " frame " << picked[k];
  }
  const SequenceFeatures plain = compute_features(sub, 0, 0, false);
  for (std::size_t k = 0; k < picked.size(); ++k) {
    const Positions got = solver.solve(plain.raw(static_cast<int>(k)));
    const FrameError e = error_up_to_translation(sub.frames[k], got, solver.neighbourhood());
    EXPECT_LT(e.mean, 0.03) << s.source << " frame " << picked[k];
  }
}

TEST(RealModels, SydneyMd2HeaderFramesAndClips) {
  const std::string path = seqtest::sydney_path();
  if (path.empty()) return;
  const MeshSequence s = read_md2(path);
  EXPECT_GT(s.frame_count(), 100);
  EXPECT_GT(s.vertex_count(), 100);
  ASSERT_NE(find_clip(s, "stand"), nullptr);
  ASSERT_NE(find_clip(s, "run"), nullptr);
  EXPECT_EQ(find_clip(s, "stand")->first, 0);
  int covered = 0;
  for (const auto& c : s.clips) covered += c.count;
  EXPECT_EQ(covered, s.frame_count());
}

// faerie.md2 numbers its three deaths death101.., death201.., death301..:
// three clips, not one that jumps from a lying pose to a standing one.
TEST(RealModels, FaerieMd2DeathsAreThreeClips) {
  const std::string path = "/usr/share/doc/libirrlicht-dev/media/faerie.md2.gz";
  if (!std::filesystem::exists(path)) {
    ADD_FAILURE() << path << " is missing: install the Debian package libirrlicht-doc";
    return;
  }
  const MeshSequence s = read_md2(path);
  EXPECT_EQ(find_clip(s, "death"), nullptr);
  for (const auto& [name, count] : {std::pair{"death1", 6}, {"death2", 6}, {"death3", 8},
                                    {"pain1", 4}, {"pain3", 4}, {"stand", 40}}) {
    const Clip* c = find_clip(s, name);
    ASSERT_NE(c, nullptr) << name;
    EXPECT_EQ(c->count, count) << name;
  }
}

TEST(RealModels, SydneyRoundTrip) {
  const std::string path = seqtest::sydney_path();
  if (path.empty()) return;
  expect_round_trip(read_mesh_sequence(path));
}

TEST(RealModels, SargeLowerMd3ClipsFromAnimationCfg) {
  const std::string path = seqtest::sarge_lower_path();
  if (path.empty()) return;
  const MeshSequence s = read_md3(path);
  // lower.md3 holds the BOTH_ frames (0..89) and the LEGS_ frames moved
  // down by LEGS_WALKCR - TORSO_GESTURE = 153 - 90 = 63.
  const Clip* walk = find_clip(s, "LEGS_WALK");
  const Clip* turn = find_clip(s, "LEGS_TURN");
  const Clip* death = find_clip(s, "BOTH_DEATH2");
  ASSERT_NE(walk, nullptr);
  ASSERT_NE(turn, nullptr);
  ASSERT_NE(death, nullptr);
  EXPECT_EQ(find_clip(s, "TORSO_GESTURE"), nullptr);
  EXPECT_EQ(walk->first, 161 - 63);
  EXPECT_EQ(walk->count, 12);
  EXPECT_DOUBLE_EQ(walk->fps, 20.0);
  EXPECT_EQ(death->first, 30);
  // LEGS_TURN (254, 7 frames) ends at 261 - 63 = 198; the file carries 15
  // more frames after it that no clip names.
  EXPECT_EQ(turn->first, 254 - 63);
  EXPECT_EQ(turn->first + turn->count, 198);
  EXPECT_EQ(s.frame_count(), 213);
}

TEST(RealModels, SargeLowerRoundTrip) {
  const std::string path = seqtest::sarge_lower_path();
  if (path.empty()) return;
  expect_round_trip(read_mesh_sequence(path));
}

}  // namespace
}  // namespace animrt::seqnet
