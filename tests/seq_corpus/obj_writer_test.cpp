// The OBJ writers: what they write parses back (by a small reader of this
// test's own) with the same vertices and faces, one file per frame in
// frame order, and no frame of an earlier sequence is left behind.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "animrt/controllers/seqnet/mesh_io.hpp"

namespace {

namespace fs = std::filesystem;
using animrt::seqnet::MeshSequence;
using animrt::seqnet::Positions;

struct ParsedObj {
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> f;  // 0-based
};

ParsedObj parse_obj(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  ParsedObj out;
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      Eigen::Vector3d p;
      ls >> p.x() >> p.y() >> p.z();
      EXPECT_FALSE(ls.fail()) << line;
      out.v.push_back(p);
    } else if (tag == "f") {
      std::array<int, 3> t{};
      ls >> t[0] >> t[1] >> t[2];
      EXPECT_FALSE(ls.fail()) << line;
      std::string extra;
      EXPECT_FALSE(ls >> extra) << "not a triangle: " << line;
      for (int& i : t) --i;
      out.f.push_back(t);
    } else {
      EXPECT_TRUE(tag.empty() || tag[0] == '#') << line;
    }
  }
  return out;
}

// A tetrahedron moving through `frames` frames, with coordinates that do not
// print short.
MeshSequence moving_tetrahedron(int frames) {
  MeshSequence s;
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (int f = 0; f < frames; ++f) {
    Positions p(3, 4);
    p << 0, 1, 0, 0,  //
        0, 0, 1, 0,   //
        0, 0, 0, 1;
    p.array() += 0.1234567891 * f - 12.000000317;
    p(0, 1) = 1e-7 * (f + 1);
    s.frames.push_back(p);
  }
  return s;
}

class ObjWriter : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / "obj_writer_test";
  void SetUp() override { fs::remove_all(dir); }
  void TearDown() override { fs::remove_all(dir); }
};

TEST_F(ObjWriter, SequenceParsesBackFramesInOrder) {
  const MeshSequence s = moving_tetrahedron(3);
  animrt::seqnet::write_obj_sequence((dir / "seq").string(), s);
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir / "seq")) names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names,
            (std::vector<std::string>{"frame_0000.obj", "frame_0001.obj", "frame_0002.obj"}));
  for (int f = 0; f < 3; ++f) {
    const ParsedObj obj = parse_obj(dir / "seq" / names[static_cast<std::size_t>(f)]);
    ASSERT_EQ(obj.v.size(), 4u);
    for (int v = 0; v < 4; ++v) {
      const Eigen::Vector3d want = s.frames[static_cast<std::size_t>(f)].col(v);
      EXPECT_LE((obj.v[static_cast<std::size_t>(v)] - want).norm(), 1e-8 * (1.0 + want.norm()))
          << "frame " << f << " vertex " << v;
    }
    EXPECT_EQ(obj.f, s.triangles);
  }
}

TEST_F(ObjWriter, RewritingRemovesFramesOfALongerSequence) {
  animrt::seqnet::write_obj_sequence((dir / "seq").string(), moving_tetrahedron(5));
  std::ofstream(dir / "seq" / "notes.txt") << "kept";
  animrt::seqnet::write_obj_sequence((dir / "seq").string(), moving_tetrahedron(2));
  int frames = 0;
  for (const auto& e : fs::directory_iterator(dir / "seq"))
    frames += e.path().extension() == ".obj";
  EXPECT_EQ(frames, 2);
  EXPECT_TRUE(fs::exists(dir / "seq" / "notes.txt"));
}

TEST_F(ObjWriter, SingleFrameAndBadInput) {
  fs::create_directories(dir);
  const MeshSequence s = moving_tetrahedron(2);
  animrt::seqnet::write_obj((dir / "one.obj").string(), s, 1);
  const ParsedObj obj = parse_obj(dir / "one.obj");
  ASSERT_EQ(obj.v.size(), 4u);
  EXPECT_NEAR(obj.v[0].x(), s.frames[1](0, 0), 1e-8 * std::fabs(s.frames[1](0, 0)));
  EXPECT_THROW(animrt::seqnet::write_obj((dir / "x.obj").string(), s, 2), std::out_of_range);
  MeshSequence bad = s;
  bad.triangles.push_back({0, 1, 4});
  EXPECT_THROW(animrt::seqnet::write_obj_sequence((dir / "bad").string(), bad),
               std::invalid_argument);
  EXPECT_THROW(animrt::seqnet::write_obj((dir / "no_such_dir" / "x.obj").string(), s, 0),
               std::runtime_error);
}

}  // namespace
