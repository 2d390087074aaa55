#include "animrt/controllers/seqnet/feature_file.hpp"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "file_bytes.hpp"

namespace animrt::seqnet {
namespace {

constexpr std::uint32_t kMaxClipName = 256;

struct Writer {
  std::vector<std::uint8_t> bytes;
  void u32(std::uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<std::uint8_t>(bits >> (8 * k)));
  }
};

struct Reader {
  const detail::ByteView& in;
  std::uint64_t at = 0;
  std::uint32_t u32(const std::string& key, const char* what) {
    in.need(at, 1, 4, key, what);
    const std::uint32_t v = in.u32(at);
    at += 4;
    return v;
  }
  double f64_unchecked() {
    const std::uint64_t bits =
        static_cast<std::uint64_t>(in.u32(at)) | static_cast<std::uint64_t>(in.u32(at + 4)) << 32;
    at += 8;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
};

// The number of connected pieces of the triangles (an unused vertex is a
// piece of its own), as Neighbourhood counts them.
std::uint32_t count_pieces(std::uint32_t vertices, const Triangles& triangles) {
  std::vector<std::uint32_t> parent(vertices);
  for (std::uint32_t i = 0; i < vertices; ++i) parent[i] = i;
  auto root = [&parent](std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::uint32_t pieces = vertices;
  for (const auto& t : triangles) {
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t a = root(static_cast<std::uint32_t>(t[k]));
      const std::uint32_t b = root(static_cast<std::uint32_t>(t[k + 1]));
      if (a != b) {
        parent[a] = b;
        --pieces;
      }
    }
  }
  return pieces;
}

void read_placement(Reader& r, const std::string& file, SequenceFeatures& out,
                    std::uint32_t pieces) {
  const std::uint32_t expected =
      count_pieces(static_cast<std::uint32_t>(out.rest.cols()), out.triangles);
  if (pieces != expected) {
    detail::fail(file, "header",
                 "placement of " + std::to_string(pieces) + " pieces, the triangles make " +
                     std::to_string(expected));
  }
  out.placement.reserve(out.frames.size());
  for (std::size_t f = 0; f < out.frames.size(); ++f) {
    Eigen::Matrix3Xd p(3, 1 + pieces);
    for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] = r.f64_unchecked();
    if (!p.allFinite())
      detail::fail(file, "frame " + std::to_string(f), "a placement is not finite");
    out.placement.push_back(std::move(p));
  }
}

}  // namespace

void write_feature_file(const std::string& file, const SequenceFeatures& f) {
  Writer w;
  w.bytes.insert(w.bytes.end(), kFeatureFileMagic, kFeatureFileMagic + 8);
  // Features without a placement (made in memory) keep the version-1 layout.
  const bool placed = !f.placement.empty();
  for (const auto& p : f.placement) {
    if (f.placement.size() != f.frames.size() || p.cols() != f.placement.front().cols())
      throw std::invalid_argument(file + ": placement does not match the frames");
  }
  w.u32(placed ? kFeatureFileVersion : 1);
  w.u32(static_cast<std::uint32_t>(f.vertex_count()));
  w.u32(static_cast<std::uint32_t>(f.triangles.size()));
  w.u32(static_cast<std::uint32_t>(f.frames.size()));
  w.u32(static_cast<std::uint32_t>(f.clips.size()));
  w.u32(kFeatureDims);
  if (placed) w.u32(static_cast<std::uint32_t>(f.placement.front().cols() - 1));
  for (Eigen::Index i = 0; i < f.rest.size(); ++i) w.f64(f.rest.data()[i]);
  for (const auto& t : f.triangles) {
    for (int c : t) w.u32(static_cast<std::uint32_t>(c));
  }
  for (const Clip& c : f.clips) {
    const std::string name = c.name.substr(0, kMaxClipName);
    w.u32(static_cast<std::uint32_t>(name.size()));
    w.bytes.insert(w.bytes.end(), name.begin(), name.end());
    w.i32(c.first);
    w.i32(c.count);
    w.f64(c.fps);
  }
  for (Eigen::Index i = 0; i < f.scale.low.size(); ++i) w.f64(f.scale.low.data()[i]);
  for (Eigen::Index i = 0; i < f.scale.high.size(); ++i) w.f64(f.scale.high.data()[i]);
  for (const auto& frame : f.frames) {
    for (Eigen::Index i = 0; i < frame.size(); ++i) w.f64(frame.data()[i]);
  }
  for (const auto& p : f.placement) {
    for (Eigen::Index i = 0; i < p.size(); ++i) w.f64(p.data()[i]);
  }
  w.u32(static_cast<std::uint32_t>(crc32(0L, w.bytes.data(), static_cast<uInt>(w.bytes.size()))));
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(file + ": cannot write");
  out.write(reinterpret_cast<const char*>(w.bytes.data()),
            static_cast<std::streamsize>(w.bytes.size()));
  if (!out) throw std::runtime_error(file + ": write failed");
}

SequenceFeatures read_feature_file(const std::string& file) {
  const std::vector<std::uint8_t> bytes =
      detail::read_file_bytes(file, detail::kMaxFeatureFileBytes);
  const detail::ByteView in(bytes, file);
  in.need(0, 1, 32, "header", "the header");
  if (std::memcmp(bytes.data(), kFeatureFileMagic, 8) != 0) {
    detail::fail(file, "header", "not an animrt feature file (wrong magic)");
  }
  Reader r{in, 8};
  const std::uint32_t version = r.u32("header", "version");
  if (version != 1 && version != kFeatureFileVersion) {
    detail::fail(file, "header",
                 "feature file version " + std::to_string(version) + ", this build reads " +
                     std::to_string(kFeatureFileVersion) + " and 1");
  }
  const std::uint32_t v = r.u32("header", "vertex count");
  const std::uint32_t t = r.u32("header", "triangle count");
  const std::uint32_t n = r.u32("header", "frame count");
  const std::uint32_t c = r.u32("header", "clip count");
  const std::uint32_t dims = r.u32("header", "dimensions");
  const std::uint32_t pieces = version >= 2 ? r.u32("header", "piece count") : 0;
  if (dims != kFeatureDims) {
    detail::fail(file, "header", std::to_string(dims) + " numbers per vertex, expected 9");
  }
  if (v == 0 || t == 0 || n == 0)
    detail::fail(file, "header", "empty vertex, triangle or frame count");
  // The checksum covers everything before its own 4 bytes.
  if (bytes.size() < 36) detail::fail(file, "checksum", "file is truncated");
  const std::uint32_t stored = in.u32(bytes.size() - 4);
  const auto computed =
      static_cast<std::uint32_t>(crc32(0L, bytes.data(), static_cast<uInt>(bytes.size() - 4)));

  SequenceFeatures out;
  in.need(r.at, v, 24, "header", "the template vertices");
  out.rest.resize(3, v);
  for (Eigen::Index i = 0; i < out.rest.size(); ++i) out.rest.data()[i] = r.f64_unchecked();
  in.need(r.at, t, 12, "header", "the triangles");
  out.triangles.resize(t);
  for (std::uint32_t k = 0; k < t; ++k) {
    for (int corner = 0; corner < 3; ++corner) {
      const std::uint32_t index = in.u32(r.at);
      r.at += 4;
      if (index >= v) {
        detail::fail(file, "triangle " + std::to_string(k),
                     "vertex " + std::to_string(index) + " is out of range (" + std::to_string(v) +
                         " vertices)");
      }
      out.triangles[k][corner] = static_cast<int>(index);
    }
  }
  in.need(r.at, c, 20, "header", "the clips");
  for (std::uint32_t k = 0; k < c; ++k) {
    const std::string key = "clip " + std::to_string(k);
    const std::uint32_t length = r.u32(key, "clip name length");
    if (length > kMaxClipName) detail::fail(file, key, "clip name longer than 256 bytes");
    in.need(r.at, 1, length + 16u, key, "the clip");
    Clip clip;
    clip.name.assign(reinterpret_cast<const char*>(bytes.data() + r.at), length);
    r.at += length;
    clip.first = in.i32(r.at);
    clip.count = in.i32(r.at + 4);
    r.at += 8;
    clip.fps = r.f64_unchecked();
    if (clip.first < 0 || clip.count < 1 ||
        static_cast<std::uint64_t>(clip.first) + static_cast<std::uint64_t>(clip.count) > n) {
      detail::fail(file, key, "frames out of range of the file's " + std::to_string(n) + " frames");
    }
    out.clips.push_back(clip);
  }
  const std::uint64_t per_frame = std::uint64_t{v} * kFeatureDims;
  in.need(r.at, 2 + std::uint64_t{n}, per_frame * 8, "header", "the normalisation and the frames");
  if (pieces > v) detail::fail(file, "header", "more pieces than vertices");
  const std::uint64_t placement_bytes =
      version >= 2 ? std::uint64_t{n} * (1 + std::uint64_t{pieces}) * 24 : 0;
  in.need(r.at + (2 + std::uint64_t{n}) * per_frame * 8, 1, placement_bytes, "header",
          "the placement");
  if (r.at + (2 + std::uint64_t{n}) * per_frame * 8 + placement_bytes + 4 != bytes.size()) {
    detail::fail(file, "header", "file length does not match its counts (trailing bytes)");
  }
  if (stored != computed) detail::fail(file, "checksum", "CRC-32 mismatch: the file is corrupt");
  out.scale.low.resize(kFeatureDims, v);
  out.scale.high.resize(kFeatureDims, v);
  for (Eigen::Index i = 0; i < out.scale.low.size(); ++i)
    out.scale.low.data()[i] = r.f64_unchecked();
  for (Eigen::Index i = 0; i < out.scale.high.size(); ++i)
    out.scale.high.data()[i] = r.f64_unchecked();
  if (!out.scale.low.allFinite() || !out.scale.high.allFinite() || !out.rest.allFinite()) {
    detail::fail(file, "header", "the template or the normalisation holds a non-finite number");
  }
  out.frames.reserve(n);
  for (std::uint32_t f = 0; f < n; ++f) {
    FeatureFrame frame(kFeatureDims, v);
    for (Eigen::Index i = 0; i < frame.size(); ++i) frame.data()[i] = r.f64_unchecked();
    if (!frame.allFinite())
      detail::fail(file, "frame " + std::to_string(f), "a feature is not finite");
    out.frames.push_back(std::move(frame));
  }
  if (version >= 2) read_placement(r, file, out, pieces);
  return out;
}

}  // namespace animrt::seqnet
