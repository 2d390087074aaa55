// The binary feature file: round trip and broken files.

#include "animrt/controllers/seqnet/feature_file.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "animrt/core/error.hpp"
#include "animrt/learn/seqnet/shapes.hpp"
#include "seq_test_util.hpp"

namespace animrt::seqnet {
namespace {

SequenceFeatures sample() {
  MeshSequence bar = make_twisting_bar(4, 5, 2.0, std::numbers::pi, 5);
  bar.clips = {Clip{"twist", 0, 5, 25.0}, Clip{"tail", 3, 2, 0.0}};
  return compute_features(bar);
}

std::vector<std::uint8_t> load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

std::string error_reading(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  const std::string path = seqtest::temp_path(name);
  seqtest::Bytes b;
  b.data = bytes;
  b.save(path);
  try {
    read_feature_file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(FeatureFile, RoundTripKeepsEverything) {
  const SequenceFeatures f = sample();
  const std::string path = seqtest::temp_path("f.bin");
  write_feature_file(path, f);
  const SequenceFeatures g = read_feature_file(path);
  EXPECT_EQ(g.rest, f.rest);
  EXPECT_EQ(g.triangles, f.triangles);
  ASSERT_EQ(g.clips.size(), 2u);
  EXPECT_EQ(g.clips[1].name, "tail");
  EXPECT_EQ(g.clips[1].first, 3);
  EXPECT_EQ(g.clips[0].fps, 25.0);
  EXPECT_EQ(g.scale.low, f.scale.low);
  EXPECT_EQ(g.scale.high, f.scale.high);
  ASSERT_EQ(g.frames.size(), f.frames.size());
  for (std::size_t k = 0; k < f.frames.size(); ++k) EXPECT_EQ(g.frames[k], f.frames[k]);
  ASSERT_EQ(g.placement.size(), f.frames.size());
  for (std::size_t k = 0; k < f.frames.size(); ++k) EXPECT_EQ(g.placement[k], f.placement[k]);
}

TEST(FeatureFile, BrokenFilesAreClearErrors) {
  const std::string path = seqtest::temp_path("good.bin");
  write_feature_file(path, sample());
  const std::vector<std::uint8_t> good = load(path);

  auto cut = good;
  cut.resize(good.size() - 100);
  std::string e = error_reading(cut, "cut.bin");
  EXPECT_NE(e.find("cut.bin"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;

  auto flipped = good;
  flipped[good.size() - 50] ^= 0x10;  // inside the last frame's features
  e = error_reading(flipped, "flipped.bin");
  EXPECT_NE(e.find("checksum"), std::string::npos) << e;

  auto magic = good;
  magic[0] = 'X';
  EXPECT_NE(error_reading(magic, "magic.bin").find("magic"), std::string::npos);

  auto version = good;
  version[8] = 3;
  EXPECT_NE(error_reading(version, "version.bin").find("version 3"), std::string::npos);

  auto longer = good;
  longer.push_back(0);
  EXPECT_NE(error_reading(longer, "longer.bin").find("does not match"), std::string::npos);

  auto frames = good;
  frames[20] = 200;  // frame count 200: more frames than the file holds
  e = error_reading(frames, "frames.bin");
  EXPECT_NE(e.find("frames.bin"), std::string::npos) << e;
  EXPECT_FALSE(e.empty());
}

}  // namespace
}  // namespace animrt::seqnet
