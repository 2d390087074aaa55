// animation.cfg beside an MD3 model (controllers/seqnet/md3_reader.cpp): the
// input is the cfg; the model is a fixed, valid lower.md3 of 64 frames, so
// every clip line is checked against a real frame count.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "animrt/core/error.hpp"
#include "fuzz_support.hpp"

namespace {

void put32(std::vector<char>& b, std::int32_t v) {
  const auto u = static_cast<std::uint32_t>(v);
  for (int k = 0; k < 4; ++k) b.push_back(static_cast<char>(u >> (8 * k)));
}
void put16(std::vector<char>& b, std::int16_t v) {
  const auto u = static_cast<std::uint16_t>(v);
  b.push_back(static_cast<char>(u & 0xff));
  b.push_back(static_cast<char>(u >> 8));
}
void text(std::vector<char>& b, const char* s, std::size_t width) {
  const std::size_t n = std::strlen(s);
  for (std::size_t k = 0; k < width; ++k) b.push_back(k < n ? s[k] : '\0');
}

// One surface, a tetrahedron, 64 frames (MD3 layout as in md3_reader.cpp).
std::string write_model() {
  constexpr int kFrames = 64, kVerts = 4, kTris = 4;
  const int tris[kTris][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const int verts[kVerts][3] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
  std::vector<char> b;
  const int ofs_frames = 108, ofs_surfaces = ofs_frames + 56 * kFrames;
  text(b, "IDP3", 4);
  put32(b, 15);
  text(b, "fuzz", 64);
  for (int v : {0, kFrames, 0, 1, 0, ofs_frames, ofs_surfaces, ofs_surfaces, 0}) put32(b, v);
  for (int f = 0; f < kFrames; ++f) {
    for (int k = 0; k < 10; ++k) put32(b, 0);
    text(b, "frame", 16);
  }
  const int ofs_tris = 108, ofs_st = ofs_tris + 12 * kTris, ofs_xyz = ofs_st + 8 * kVerts;
  const int ofs_end = ofs_xyz + 8 * kVerts * kFrames;
  text(b, "IDP3", 4);
  text(b, "body", 64);
  for (int v : {0, kFrames, 0, kVerts, kTris, ofs_tris, ofs_st, ofs_st, ofs_xyz, ofs_end})
    put32(b, v);
  for (const auto& t : tris)
    for (int c : t) put32(b, c);
  for (int k = 0; k < 2 * kVerts; ++k) put32(b, 0);
  for (int f = 0; f < kFrames; ++f) {
    for (const auto& v : verts) {
      for (int c : v) put16(b, static_cast<std::int16_t>(c * 64 + f));
      put16(b, 0);
    }
  }
  const std::string path = animrt::fuzz::work_dir() + "/lower.md3";
  std::ofstream(path, std::ios::binary).write(b.data(), static_cast<std::streamsize>(b.size()));
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string model = write_model();
  (void)animrt::fuzz::write_input(data, size, "animation.cfg");
  try {
    (void)animrt::seqnet::read_md3(model);
  } catch (const animrt::InputError&) {
  }
  return 0;
}
