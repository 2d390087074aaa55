// Quake II MD2: a 68-byte header ("IDP2", version 8, counts and offsets),
// triangles of vertex and texture-coordinate indices, and frames of
// byte-compressed vertices (position = byte * scale + translate) with a
// normal index we ignore. Frame names give the clips.

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "clip_names.hpp"
#include "file_bytes.hpp"
#include "mesh_checks.hpp"

namespace animrt::seqnet {
namespace {

constexpr std::int32_t kMd2MaxVerts = 2048;
constexpr std::int32_t kMd2MaxTriangles = 4096;
constexpr std::int32_t kMd2MaxFrames = 512;

}  // namespace

MeshSequence read_md2(const std::string& file) {
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(file);
  const detail::ByteView in(bytes, file);
  in.need(0, 1, 68, "header", "the header");
  if (in.name(0, 4) != "IDP2") {
    detail::fail(file, "header", "not an MD2 file (magic is not IDP2)");
  }
  const std::int32_t version = in.i32(4);
  if (version != 8)
    detail::fail(file, "header", "MD2 version " + std::to_string(version) + ", expected 8");
  const std::int32_t frame_size = in.i32(16);
  const std::int32_t num_xyz = in.i32(24);
  const std::int32_t num_st = in.i32(28);
  const std::int32_t num_tris = in.i32(32);
  const std::int32_t num_frames = in.i32(40);
  const std::int32_t ofs_tris = in.i32(52);
  const std::int32_t ofs_frames = in.i32(56);
  // Each frame's vertices grow sixfold in memory (4 bytes to 3 doubles), so
  // the counts are held to the Quake II engine's limits (qfiles.h) as well
  // as to the file's size.
  auto in_range = [&](std::int32_t value, std::int32_t high, const char* what) {
    if (value <= 0 || value > high) {
      detail::fail(file, "header",
                   std::string(what) + " is " + std::to_string(value) + ", expected 1.." +
                       std::to_string(high));
    }
  };
  in_range(num_xyz, kMd2MaxVerts, "vertex count");
  in_range(num_tris, kMd2MaxTriangles, "triangle count");
  in_range(num_frames, kMd2MaxFrames, "frame count");
  if (num_st < 0) detail::fail(file, "header", "texture coordinate count is negative");
  if (ofs_tris < 68 || ofs_frames < 68)
    detail::fail(file, "header", "an offset points into the header");
  const std::int64_t expected_frame = 40 + 4 * static_cast<std::int64_t>(num_xyz);
  if (frame_size != expected_frame) {
    detail::fail(file, "header",
                 "frame size " + std::to_string(frame_size) + " does not match " +
                     std::to_string(num_xyz) + " vertices (expected " +
                     std::to_string(expected_frame) + ")");
  }
  in.need(static_cast<std::uint64_t>(ofs_tris), static_cast<std::uint64_t>(num_tris), 12, "header",
          "the triangles");
  in.need(static_cast<std::uint64_t>(ofs_frames), static_cast<std::uint64_t>(num_frames),
          static_cast<std::uint64_t>(frame_size), "header", "the frames");

  MeshSequence out;
  out.source = file;
  out.triangles.reserve(static_cast<std::size_t>(num_tris));
  for (std::int32_t t = 0; t < num_tris; ++t) {
    const std::uint64_t at =
        static_cast<std::uint64_t>(ofs_tris) + 12u * static_cast<std::uint64_t>(t);
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      tri[k] = static_cast<std::uint16_t>(in.i16(at + 2u * static_cast<unsigned>(k)));
      if (tri[k] >= num_xyz) {
        detail::fail(file, "triangle " + std::to_string(t),
                     "vertex index " + std::to_string(tri[k]) + " is out of range (" +
                         std::to_string(num_xyz) + " vertices)");
      }
    }
    out.triangles.push_back(tri);
  }
  std::vector<std::string> names;
  out.frames.reserve(static_cast<std::size_t>(num_frames));
  for (std::int32_t f = 0; f < num_frames; ++f) {
    const std::uint64_t at = static_cast<std::uint64_t>(ofs_frames) +
                             static_cast<std::uint64_t>(frame_size) * static_cast<std::uint64_t>(f);
    Eigen::Vector3d scale, translate;
    for (int k = 0; k < 3; ++k) {
      scale[k] = in.f32(at + 4u * static_cast<unsigned>(k));
      translate[k] = in.f32(at + 12u + 4u * static_cast<unsigned>(k));
    }
    if (!scale.allFinite() || !translate.allFinite()) {
      detail::fail(file, "frame " + std::to_string(f), "scale or translate is not finite");
    }
    names.push_back(in.name(at + 24, 16));
    Positions frame(3, num_xyz);
    for (std::int32_t i = 0; i < num_xyz; ++i) {
      const std::uint64_t v = at + 40u + 4u * static_cast<std::uint64_t>(i);
      for (int k = 0; k < 3; ++k) {
        frame(k, i) =
            static_cast<double>(in.u8(v + static_cast<unsigned>(k))) * scale[k] + translate[k];
      }
      // Byte 3 is the index of a precomputed normal: not used.
    }
    out.frames.push_back(std::move(frame));
  }
  out.clips = detail::clips_from_frame_names(names);
  detail::merge_coincident(out, std::vector<int>(static_cast<std::size_t>(num_xyz), 0));
  detail::detach_non_manifold(out);
  detail::validate_mesh(out, file);
  return out;
}

}  // namespace animrt::seqnet
