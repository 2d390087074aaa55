// The mesh readers on small files written byte by byte from the format
// descriptions, and on broken ones.

#include <gtest/gtest.h>
#include <zlib.h>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"
#include "seq_test_util.hpp"
#include "support/hostile_files.hpp"

namespace animrt::seqnet {
namespace {

using seqtest::Bytes;

// A tetrahedron whose vertex 4 duplicates vertex 0 (a texture seam copy),
// used by the last triangle instead of 0.
const int kTetraVerts[5][3] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}, {0, 0, 0}};
const int kTetraTris[4][3] = {{0, 2, 1}, {0, 1, 3}, {4, 3, 2}, {1, 2, 3}};

struct Md2Frame {
  float scale[3];
  float translate[3];
  std::string name;
};

Bytes make_md2(const std::vector<Md2Frame>& frames, int version = 8) {
  Bytes b;
  const int verts = 5, tris = 4, frame_size = 40 + 4 * verts;
  const int ofs_tris = 68, ofs_frames = ofs_tris + 12 * tris;
  const int ofs_end = ofs_frames + frame_size * static_cast<int>(frames.size());
  b.text("IDP2", 4);
  for (int v : {version, 64, 64, frame_size, 0, verts, 0, tris, 0, static_cast<int>(frames.size()),
                68, 68, ofs_tris, ofs_frames, ofs_end, ofs_end}) {
    b.i32(v);
  }
  for (const auto& t : kTetraTris) {
    for (int c : t) b.i16(static_cast<std::int16_t>(c));
    for (int k = 0; k < 3; ++k) b.i16(0);  // texture coordinate indices
  }
  for (const auto& f : frames) {
    for (float s : f.scale) b.f32(s);
    for (float t : f.translate) b.f32(t);
    b.text(f.name, 16);
    for (const auto& v : kTetraVerts) {
      for (int c : v) b.u8(static_cast<std::uint8_t>(c));
      b.u8(200);  // normal index: ignored
    }
  }
  return b;
}

std::vector<Md2Frame> three_frames() {
  return {{{1, 1, 1}, {0, 0, 0}, "run1"},
          {{0.5f, 1, 2}, {1, 2, 3}, "run2"},
          {{1, 1, 1}, {0, 0, 5}, "jump1"}};
}

TEST(Md2Reader, HeaderFramesScaleTranslateSeamsAndClips) {
  const std::string path = seqtest::temp_path("tetra.md2");
  make_md2(three_frames()).save(path);
  const MeshSequence s = read_md2(path);
  ASSERT_EQ(s.frame_count(), 3);
  EXPECT_EQ(s.vertex_count(), 4);  // the seam copy merged
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.triangles[2], (std::array<int, 3>{0, 3, 2}));
  // Frame 1: byte * (0.5, 1, 2) + (1, 2, 3).
  EXPECT_EQ(s.frames[1].col(1), Eigen::Vector3d(6, 2, 3));
  EXPECT_EQ(s.frames[1].col(3), Eigen::Vector3d(1, 2, 23));
  EXPECT_EQ(s.frames[2].col(2), Eigen::Vector3d(0, 10, 5));
  ASSERT_EQ(s.clips.size(), 2u);
  EXPECT_EQ(s.clips[0].name, "run");
  EXPECT_EQ(s.clips[0].first, 0);
  EXPECT_EQ(s.clips[0].count, 2);
  EXPECT_EQ(s.clips[1].name, "jump");
  EXPECT_EQ(s.clips[1].first, 2);
}

// Quake II numbers the frames of each animation from 01 after its own
// number (Irrlicht's faerie: death101..death106, death201..); a number that
// does not follow on starts a new clip.
TEST(Md2Reader, ANumberThatDoesNotFollowOnStartsAClip) {
  const std::string path = seqtest::temp_path("deaths.md2");
  std::vector<Md2Frame> frames;
  for (const char* name : {"death101", "death102", "death201", "death202", "death203", "run1",
                           "run2", "run1", "stand1", "stand2", "stand3"}) {
    frames.push_back({{1, 1, 1}, {0, 0, 0}, name});
  }
  make_md2(frames).save(path);
  const MeshSequence s = read_md2(path);
  std::vector<std::string> got;
  for (const auto& c : s.clips)
    got.push_back(c.name + " " + std::to_string(c.first) + "+" + std::to_string(c.count));
  EXPECT_EQ(got, (std::vector<std::string>{"death1 0+2", "death2 2+3", "run_1 5+2", "run_2 7+1",
                                           "stand 8+3"}));
}

TEST(Md2Reader, GzipIsTransparent) {
  const Bytes b = make_md2(three_frames());
  const std::string path = seqtest::temp_path("tetra.md2.gz");
  gzFile out = gzopen(path.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  gzwrite(out, b.data.data(), static_cast<unsigned>(b.size()));
  gzclose(out);
  const MeshSequence s = read_mesh_sequence(path);
  EXPECT_EQ(s.frame_count(), 3);
  EXPECT_EQ(s.frames[1].col(1), Eigen::Vector3d(6, 2, 3));
  // A truncated gzip stream is an error naming the file.
  std::vector<std::uint8_t> packed;
  {
    std::ifstream in(path, std::ios::binary);
    packed.assign(std::istreambuf_iterator<char>(in), {});
  }
  Bytes cut;
  cut.data.assign(packed.begin(), packed.begin() + static_cast<long>(packed.size() / 2));
  const std::string cut_path = seqtest::temp_path("cut.md2.gz");
  cut.save(cut_path);
  try {
    read_mesh_sequence(cut_path);
    FAIL() << "truncated gzip accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.md2.gz"), std::string::npos) << e.what();
  }
}

std::string error_of(const std::string& path, MeshSequence (*reader)(const std::string&)) {
  try {
    reader(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Md2Reader, BadFilesNameFileAndPart) {
  const std::string path = seqtest::temp_path("bad.md2");
  Bytes b = make_md2(three_frames());
  Bytes truncated = b;
  truncated.data.resize(b.size() - 10);
  truncated.save(path);
  std::string e = error_of(path, read_md2);
  EXPECT_NE(e.find("bad.md2"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;

  make_md2(three_frames(), 7).save(path);
  e = error_of(path, read_md2);
  EXPECT_NE(e.find("version 7"), std::string::npos) << e;

  Bytes magic = b;
  magic.data[3] = 'X';
  magic.save(path);
  EXPECT_NE(error_of(path, read_md2).find("IDP2"), std::string::npos);

  Bytes huge = b;
  huge.put_i32(40, 1 << 30);  // frame count far beyond the file
  huge.save(path);
  e = error_of(path, read_md2);
  EXPECT_NE(e.find("frame count is 1073741824"), std::string::npos) << e;

  Bytes index = b;
  index.data[68] = 9;  // first triangle's first vertex index: 9 of 5
  index.save(path);
  e = error_of(path, read_md2);
  EXPECT_NE(e.find("triangle 0"), std::string::npos) << e;

  // Frame 0 collapses onto a plane: every triangle has zero area there.
  auto flat = three_frames();
  flat[0].scale[2] = 0.0f;
  make_md2(flat).save(path);
  e = error_of(path, read_md2);
  EXPECT_NE(e.find("frame 0"), std::string::npos) << e;
  EXPECT_NE(e.find("zero area"), std::string::npos) << e;
}

// Two surfaces: the tetrahedron (with its seam copy) and the same shifted
// by 100 in x; xyz are int16 in 1/64 units.
Bytes make_md3(int frames, int second_surface_frames) {
  Bytes b;
  const int ofs_frames = 108, ofs_surfaces = ofs_frames + 56 * frames;
  b.text("IDP3", 4);
  b.i32(15);
  b.text("test", 64);
  for (int v : {0, frames, 0, 2, 0, ofs_frames, ofs_surfaces, ofs_surfaces, 0}) b.i32(v);
  for (int f = 0; f < frames; ++f) {
    for (int k = 0; k < 10; ++k) b.f32(0.0f);  // bounds, origin, radius
    b.text("frame", 16);
  }
  for (int s = 0; s < 2; ++s) {
    const int surface_frames = s == 0 ? frames : second_surface_frames;
    const int verts = 5, tris = 4;
    const int ofs_tris = 108, ofs_st = ofs_tris + 12 * tris, ofs_xyz = ofs_st + 8 * verts;
    const int ofs_end = ofs_xyz + 8 * verts * surface_frames;
    b.text("IDP3", 4);
    b.text(s == 0 ? "body" : "belt", 64);
    for (int v : {0, surface_frames, 0, verts, tris, ofs_tris, ofs_st, ofs_st, ofs_xyz, ofs_end})
      b.i32(v);
    for (const auto& t : kTetraTris) {
      for (int c : t) b.i32(c);
    }
    for (int k = 0; k < 2 * verts; ++k) b.f32(0.5f);  // texture coordinates
    for (int f = 0; f < surface_frames; ++f) {
      for (const auto& v : kTetraVerts) {
        b.i16(static_cast<std::int16_t>((v[0] + 100 * s) * 64));
        b.i16(static_cast<std::int16_t>(v[1] * 64 + f * 32));  // frame f moves by f / 2 in y
        b.i16(static_cast<std::int16_t>(v[2] * 64));
        b.i16(0x1234);  // packed normal: ignored
      }
    }
  }
  return b;
}

TEST(Md3Reader, SurfacesBecomePiecesOfOneMesh) {
  const std::string path = seqtest::temp_path("model.md3");
  make_md3(2, 2).save(path);
  const MeshSequence s = read_md3(path);
  ASSERT_EQ(s.frame_count(), 2);
  EXPECT_EQ(s.vertex_count(), 8);  // 2 x (5 - the seam copy)
  ASSERT_EQ(s.triangles.size(), 8u);
  EXPECT_EQ(s.triangles[4], (std::array<int, 3>{4, 6, 5}));
  EXPECT_EQ(s.frames[0].col(5), Eigen::Vector3d(110, 0, 0));
  EXPECT_EQ(s.frames[1].col(3), Eigen::Vector3d(0, 0.5, 10));
  EXPECT_TRUE(s.clips.empty());  // no animation.cfg here
}

TEST(Md3Reader, BadFilesNameFileAndPart) {
  const std::string path = seqtest::temp_path("bad.md3");
  make_md3(2, 3).save(path);
  std::string e = error_of(path, read_md3);
  EXPECT_NE(e.find("bad.md3"), std::string::npos) << e;
  EXPECT_NE(e.find("surface 1"), std::string::npos) << e;
  EXPECT_NE(e.find("3 frames"), std::string::npos) << e;

  Bytes b = make_md3(2, 2);
  Bytes cut = b;
  cut.data.resize(b.size() - 4);
  cut.save(path);
  e = error_of(path, read_md3);
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;

  Bytes version = b;
  version.put_i32(4, 16);
  version.save(path);
  EXPECT_NE(error_of(path, read_md3).find("version 16"), std::string::npos);

  Bytes count = b;
  count.put_i32(84, 1000);  // surfaces
  count.save(path);
  e = error_of(path, read_md3);
  EXPECT_NE(e.find("surface count"), std::string::npos) << e;
}

// A surface with no vertices and no triangles at the end of `b` (OpenArena's
// tony has two: l_belt and u_vest).
void add_empty_surface(Bytes& b, int frames) {
  b.text("IDP3", 4);
  b.text("l_belt", 64);
  for (int v : {0, frames, 1, 0, 0, 108, 108, 108, 108, 108}) b.i32(v);
  b.put_i32(84, 3);  // the header's surface count
}

TEST(Md3Reader, EmptySurfacesAreSkipped) {
  const std::string path = seqtest::temp_path("empty_surface.md3");
  Bytes b = make_md3(2, 2);
  add_empty_surface(b, 2);
  b.save(path);
  const MeshSequence s = read_md3(path);
  EXPECT_EQ(s.vertex_count(), 8);
  EXPECT_EQ(s.triangles.size(), 8u);
  EXPECT_EQ(s.frames[1].col(3), Eigen::Vector3d(0, 0.5, 10));

  // Vertices without triangles, or triangles without vertices, are not
  // an empty surface: still refused.
  Bytes verts_only = b;
  verts_only.put_i32(verts_only.size() - 108 + 80, 5);
  verts_only.save(path);
  std::string e = error_of(path, read_md3);
  EXPECT_NE(e.find("surface 2: triangle count is 0"), std::string::npos) << e;
  Bytes tris_only = b;
  tris_only.put_i32(tris_only.size() - 108 + 84, 1);
  tris_only.save(path);
  e = error_of(path, read_md3);
  EXPECT_NE(e.find("surface 2: vertex count is 0"), std::string::npos) << e;
}

// animation.cfg of 25 lines for a 4-frame lower.md3: BOTH_ at frames 0..1,
// TORSO_ from 2 and LEGS_WALKCR from 4 (the engine's numbering), so the legs
// move down by 2 to frames 2..3 of the file.
std::string animation_cfg(const std::string& legs_turn) {
  std::string cfg = "sex m\n// first, count, looping, fps\n";
  for (int i = 0; i < 6; ++i) cfg += "0 2 0 10\n";   // BOTH_
  for (int i = 0; i < 7; ++i) cfg += "2 1 0 10\n";   // TORSO_
  for (int i = 0; i < 11; ++i) cfg += "4 2 2 15\n";  // LEGS_WALKCR .. LEGS_IDLECR
  return cfg + legs_turn + "\t// LEGS_TURN\n";
}

TEST(Md3Reader, AClipOfNoFramesIsLeftOutAndAClipOutsideTheFileIsRefused) {
  namespace fs = std::filesystem;
  const std::string dir = seqtest::temp_path("md3_empty_clip");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string model = dir + "/lower.md3";
  make_md3(4, 4).save(model);
  // OpenArena's merman: "192 0 0 0 // LEGS_TURN", past the file's frames.
  seqtest::write_text(dir + "/animation.cfg", animation_cfg("192\t0\t0\t0"));
  const MeshSequence s = read_md3(model);
  ASSERT_EQ(s.clips.size(), 17u);  // 6 BOTH_ and 11 LEGS_, no LEGS_TURN
  EXPECT_EQ(s.clips.front().name, "BOTH_DEATH1");
  EXPECT_EQ(s.clips.back().name, "LEGS_IDLECR");
  EXPECT_EQ(s.clips.back().first, 2);
  EXPECT_EQ(s.clips.back().count, 2);

  seqtest::write_text(dir + "/animation.cfg", animation_cfg("6 2 0 10"));
  EXPECT_EQ(
      error_of(model, read_md3),
      dir + "/animation.cfg:27:1: LEGS_TURN: frames 4..5 are outside " + model + "'s 4 frames");
  seqtest::write_text(dir + "/animation.cfg", animation_cfg("5 1 0 10"));
  const MeshSequence turn = read_md3(model);
  ASSERT_EQ(turn.clips.size(), 18u);
  EXPECT_EQ(turn.clips.back().name, "LEGS_TURN");
  EXPECT_EQ(turn.clips.back().first, 3);
}

TEST(ObjReader, PolygonsNegativeIndicesAndIgnoredAttributes) {
  const std::string path = seqtest::temp_path("quad.obj");
  seqtest::write_text(path,
                      "# a pyramid on a square base\n"
                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nv 0.5 0.5 1\n"
                      "f 4/1/1 3/1/1 2/1/1 1/1/1\n"
                      "f 1//1 2//1 5//1\nf -4 -3 -1\nf 3 4 5\nf -2 -5 -1\n");
  const MeshSequence s = read_obj(path);
  EXPECT_EQ(s.vertex_count(), 5);
  ASSERT_EQ(s.triangles.size(), 6u);
  EXPECT_EQ(s.triangles[0], (std::array<int, 3>{3, 2, 1}));
  EXPECT_EQ(s.triangles[1], (std::array<int, 3>{3, 1, 0}));
  EXPECT_EQ(s.triangles[3], (std::array<int, 3>{1, 2, 4}));
  EXPECT_EQ(s.frames[0].col(4), Eigen::Vector3d(0.5, 0.5, 1));
}

TEST(ObjReader, BadFacesNameLineAndColumn) {
  const std::string path = seqtest::temp_path("bad.obj");
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  std::string e = error_of(path, read_obj);
  EXPECT_NE(e.find("bad.obj:4:7"), std::string::npos) << e;
  seqtest::write_text(path, "v 0 0 0\nv 1 0 x\n");
  EXPECT_NE(error_of(path, read_obj).find("bad.obj:2:7"), std::string::npos);
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n");
  EXPECT_NE(error_of(path, read_obj).find("repeats a vertex"), std::string::npos);
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  EXPECT_NE(error_of(path, read_obj).find("zero area"), std::string::npos);
  // Three triangles on the edge 1-2.
  seqtest::write_text(path,
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  e = error_of(path, read_obj);
  EXPECT_NE(e.find("non-manifold"), std::string::npos) << e;
  EXPECT_NE(e.find("frame 0"), std::string::npos) << e;
  // A coordinate no mesh has (1e308 made a round trip of NaN); 1e9 is kept.
  seqtest::write_text(path, "v 0 0 0\nv 1e9 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(path, read_obj), "");
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 0 -1e308 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(path, read_obj),
            path +
                ": frame 0: a vertex coordinate of 1e+308, beyond 1e9 (a kilometre in "
                "micrometres; no mesh is that large)");
}

// A key or initial frame is a pose of a model's mesh: a triangle it
// flattens (frame 28 of sydney.md2 flattens one) is not a reason to refuse
// it, since the model's template is what its features are measured against.
TEST(ObjReader, APoseMayFlattenATriangleATemplateMayNot) {
  const std::string path = seqtest::temp_path("pose.obj");
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 2 3 4\nf 1 2 3\n");
  EXPECT_EQ(error_of(path, read_obj), path + ": frame 0: triangle 2 has zero area");
  EXPECT_EQ(error_of(path, read_mesh_sequence), path + ": frame 0: triangle 2 has zero area");
  const MeshSequence pose = read_mesh_pose(path);
  EXPECT_EQ(pose.vertex_count(), 4);
  EXPECT_EQ(pose.triangles.size(), 3u);
  // Everything else is still checked.
  seqtest::write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n");
  EXPECT_NE(error_of(path, read_mesh_pose).find("repeats a vertex"), std::string::npos);
}

TEST(ObjReader, FolderInNameOrderWithOneConnectivity) {
  const std::string dir = seqtest::temp_path("objs");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string tri = "f 1 2 3\nf 1 3 4\n";
  seqtest::write_text(dir + "/b.obj", "v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\n" + tri);
  seqtest::write_text(dir + "/a.obj", "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n" + tri);
  seqtest::write_text(dir + "/notes.txt", "not a frame");
  const MeshSequence s = read_obj_sequence(dir);
  ASSERT_EQ(s.frame_count(), 2);
  EXPECT_EQ(s.frames[0](2, 0), 1.0);
  EXPECT_EQ(s.frames[1](2, 0), 2.0);
  seqtest::write_text(dir + "/c.obj", "v 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nf 1 2 3\nf 1 4 3\n");
  const std::string e = error_of(dir, read_obj_sequence);
  EXPECT_NE(e.find("c.obj"), std::string::npos) << e;
  EXPECT_NE(e.find("frame 2"), std::string::npos) << e;
  EXPECT_NE(e.find("connectivity differs"), std::string::npos) << e;
}

// Hostile inputs: every mesh reader refuses a FIFO (without blocking), a
// device and a gzip bomb, and names the file.
TEST(MeshReaders, FifoDeviceAndGzipBombAreRefusedByName) {
  namespace fs = std::filesystem;
  const std::string dir = seqtest::temp_path("hostile_meshes");
  fs::remove_all(dir);
  fs::create_directories(dir);
  // 80 MiB of zeros, past the 64 MiB inflated limit, in some 80 KB.
  animrt::test::write_gzip_bomb(dir + "/bomb.gz", std::uint64_t{80} << 20);
  for (const std::string ext : {".obj", ".md2", ".md3"}) {
    const animrt::test::UnblockedFifo fifo(dir + "/pipe" + ext);
    EXPECT_EQ(error_of(fifo.path(), read_mesh_sequence),
              fifo.path() + ": is not a regular file (FIFO)");
    EXPECT_EQ(fifo.times_opened(), 0) << ext;
    const std::string zero = dir + "/zero" + ext;
    fs::create_symlink("/dev/zero", zero);
    EXPECT_EQ(error_of(zero, read_mesh_sequence),
              zero + ": is not a regular file (character device)");
    const std::string bomb = dir + "/bomb" + ext + ".gz";
    fs::copy_file(dir + "/bomb.gz", bomb);
    EXPECT_EQ(error_of(bomb, read_mesh_sequence),
              bomb + ": gzip data inflates to more than the 64 MiB limit");
  }
}

TEST(Md2Reader, CountsBeyondTheEngineLimitsOrTheFileAreRefused) {
  const std::string path = seqtest::temp_path("counts.md2");
  // 600 frames, every byte present: more than the 512 Quake II allows.
  std::vector<Md2Frame> many(600, Md2Frame{{1, 1, 1}, {0, 0, 0}, "idle"});
  make_md2(many).save(path);
  EXPECT_EQ(error_of(path, read_md2), path + ": header: frame count is 600, expected 1..512");
  // A header that claims more frames than the file holds.
  Bytes lying = make_md2(three_frames());
  lying.put_i32(40, 500);
  lying.save(path);
  std::string e = error_of(path, read_md2);
  EXPECT_EQ(e.rfind(path + ": header: ", 0), 0u) << e;
  EXPECT_NE(e.find("the frames"), std::string::npos) << e;
  // 100000 vertices with the matching frame size, in a file of 300 bytes.
  lying = make_md2(three_frames());
  lying.put_i32(24, 100000);
  lying.put_i32(16, 40 + 4 * 100000);
  lying.save(path);
  EXPECT_EQ(error_of(path, read_md2), path + ": header: vertex count is 100000, expected 1..2048");
}

TEST(Md3Reader, AnimationCfgThatIsAFifoOrDeviceIsRefusedByName) {
  namespace fs = std::filesystem;
  const std::string dir = seqtest::temp_path("md3_cfg");
  fs::remove_all(dir);
  fs::create_directories(dir);
  make_md3(2, 2).save(dir + "/lower.md3");
  {
    const animrt::test::UnblockedFifo fifo(dir + "/animation.cfg");
    EXPECT_EQ(error_of(dir + "/lower.md3", read_md3),
              fifo.path() + ": is not a regular file (FIFO)");
    EXPECT_EQ(fifo.times_opened(), 0);
  }
  fs::create_symlink("/dev/zero", dir + "/animation.cfg");
  EXPECT_EQ(error_of(dir + "/lower.md3", read_md3),
            dir + "/animation.cfg: is not a regular file (character device)");
}

TEST(ObjReader, FolderRefusesAFrameThatIsAFifoOrADeviceByName) {
  namespace fs = std::filesystem;
  const std::string dir = seqtest::temp_path("objs_hostile");
  fs::remove_all(dir);
  fs::create_directories(dir);
  seqtest::write_text(dir + "/a.obj", "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 2 3\nf 1 3 4\n");
  {
    const animrt::test::UnblockedFifo fifo(dir + "/b.obj");
    EXPECT_EQ(error_of(dir, read_obj_sequence), fifo.path() + ": is not a regular file (FIFO)");
    EXPECT_EQ(fifo.times_opened(), 0);
  }
  fs::create_symlink("/dev/zero", dir + "/c.obj.gz");
  EXPECT_EQ(error_of(dir, read_obj_sequence),
            dir + "/c.obj.gz: is not a regular file (character device)");
  fs::remove(dir + "/c.obj.gz");
  fs::create_symlink(dir + "/gone.obj", dir + "/d.obj");
  EXPECT_EQ(error_of(dir, read_obj_sequence), dir + "/d.obj: is a broken link");
}

TEST(ObjReader, MoreVerticesOrTrianglesThanAFrameMayHaveAreRefused) {
  const std::string path = seqtest::temp_path("many.obj");
  std::string text;
  for (int i = 0; i < 1000001; ++i) text += "v 0 0 0\n";
  seqtest::write_text(path, text);
  EXPECT_EQ(error_of(path, read_obj),
            path + ": v: 1000001 vertices, more than the 1000000 a frame may have");
  // One polygon of 2000003 corners fans into 2000001 triangles.
  text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 2000003; ++i) text += " " + std::to_string(1 + i % 3);
  seqtest::write_text(path, text + "\n");
  EXPECT_EQ(error_of(path, read_obj),
            path + ":4:1: f: more than the 2000000 triangles a frame may have");
}

TEST(ObjReader, ALongTokenIsQuotedShort) {
  const std::string path = seqtest::temp_path("long_token.obj");
  seqtest::write_text(path, "v 0 0 " + std::string(60u << 20, '7') + "x\n");
  const std::string e = error_of(path, read_obj);
  EXPECT_LT(e.size(), path.size() + 200) << e.substr(0, 300);
  EXPECT_NE(e.find("characters ...]"), std::string::npos) << e.substr(0, 300);
}

}  // namespace
}  // namespace animrt::seqnet
