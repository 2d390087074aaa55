#include "animrt/controllers/seqnet/model_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "animrt/core/input_file.hpp"
#include "file_bytes.hpp"

namespace animrt::seqnet {
namespace {

constexpr std::uint32_t kMaxName = 256;
constexpr std::uint32_t kMaxRank = 4;

struct ModelWriter {
  std::vector<std::uint8_t> bytes;
  void u32(std::uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  void u64(std::uint64_t v) {
    for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f64(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u64(bits);
  }
  void f32(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u32(bits);
  }
  void name(const std::string& s) {
    const std::string n = s.substr(0, kMaxName);
    u32(static_cast<std::uint32_t>(n.size()));
    bytes.insert(bytes.end(), n.begin(), n.end());
  }
  void arrays(const std::vector<NamedArray>& list) {
    u32(static_cast<std::uint32_t>(list.size()));
    for (const NamedArray& a : list) {
      name(a.name);
      u32(static_cast<std::uint32_t>(a.shape.size()));
      for (std::int64_t d : a.shape) u64(static_cast<std::uint64_t>(d));
      for (float v : a.values) f32(v);
    }
  }
};

struct ModelReader {
  const detail::ByteView& in;
  std::uint64_t at = 0;
  std::uint32_t u32(const std::string& key, const std::string& what) {
    in.need(at, 1, 4, key, what);
    const std::uint32_t v = in.u32(at);
    at += 4;
    return v;
  }
  std::uint64_t u64(const std::string& key, const std::string& what) {
    in.need(at, 1, 8, key, what);
    const std::uint64_t v =
        static_cast<std::uint64_t>(in.u32(at)) | static_cast<std::uint64_t>(in.u32(at + 4)) << 32;
    at += 8;
    return v;
  }
  double f64(const std::string& key, const std::string& what) {
    const std::uint64_t bits = u64(key, what);
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  std::string name(const std::string& key, const std::string& what) {
    const std::uint32_t n = u32(key, what + " length");
    if (n > kMaxName) {
      detail::fail(in.file(), key,
                   what + " is " + std::to_string(n) + " bytes long (at most " +
                       std::to_string(kMaxName) + ")");
    }
    in.need(at, n, 1, key, what);
    std::string out = in.name(at, n);
    if (out.size() != n) detail::fail(in.file(), key, what + " contains a NUL byte");
    at += n;
    return out;
  }
  int bounded(const std::string& what, int low, int high) {
    const std::int32_t v = static_cast<std::int32_t>(u32("shape", what));
    if (v < low || v > high) {
      detail::fail(in.file(), "shape",
                   what + " is " + std::to_string(v) + ", expected " + std::to_string(low) + ".." +
                       std::to_string(high));
    }
    return v;
  }
  std::vector<NamedArray> arrays(const std::string& what) {
    const std::uint32_t count = u32(what, what + " count");
    // Every array takes at least 8 bytes (name length and rank).
    in.need(at, count, 8, what, what + " list");
    std::vector<NamedArray> out(count);
    for (std::uint32_t k = 0; k < count; ++k) {
      NamedArray& a = out[k];
      const std::string key = what + " " + std::to_string(k);
      a.name = name(key, "name");
      const std::string named = what + " " + a.name;
      const std::uint32_t rank = u32(named, "rank");
      if (rank > kMaxRank) {
        detail::fail(
            in.file(), named,
            "rank " + std::to_string(rank) + " (at most " + std::to_string(kMaxRank) + ")");
      }
      std::uint64_t elements = 1;
      for (std::uint32_t d = 0; d < rank; ++d) {
        const std::uint64_t n = u64(named, "dimension");
        if (n == 0 || n > (std::uint64_t{1} << 31)) {
          detail::fail(
              in.file(), named,
              "dimension " + std::to_string(d) + " is " + std::to_string(n) + ", expected 1..2^31");
        }
        elements *= n;
        if (elements > (std::uint64_t{1} << 31)) {
          detail::fail(in.file(), named, "more than 2^31 values");
        }
        a.shape.push_back(static_cast<std::int64_t>(n));
      }
      in.need(at, elements, 4, named, "values");
      a.values.resize(elements);
      for (std::uint64_t i = 0; i < elements; ++i) {
        a.values[i] = in.f32(at);
        at += 4;
        if (!std::isfinite(a.values[i])) {
          detail::fail(in.file(), named, "value " + std::to_string(i) + " is not finite");
        }
      }
    }
    return out;
  }
};

}  // namespace

const char* kind_name(ModelKind kind) { return kind == ModelKind::mesh ? "mesh" : "joints"; }

std::uint64_t connectivity_hash(int vertex_count,
                                const std::vector<std::array<int, 3>>& triangles) {
  std::uint64_t h = 14695981039346656037ULL;
  auto mix = [&h](std::uint32_t v) {
    for (int k = 0; k < 4; ++k) {
      h ^= (v >> (8 * k)) & 0xffU;
      h *= 1099511628211ULL;
    }
  };
  mix(static_cast<std::uint32_t>(vertex_count));
  for (const auto& t : triangles) {
    for (int c : t) mix(static_cast<std::uint32_t>(c));
  }
  return h;
}

std::vector<std::uint8_t> model_file_bytes(const ModelFile& m) {
  ModelWriter w;
  w.bytes.insert(w.bytes.end(), kModelFileMagic, kModelFileMagic + 8);
  w.u32(m.version);
  w.u32(static_cast<std::uint32_t>(m.shape.kind));
  const NetShape& s = m.shape;
  for (int v : {s.vertex_count, s.joint_count, s.conv_layers, s.channels, s.dense_width, s.latent,
                s.hidden, s.lstm_layers, s.window, s.stride}) {
    w.i32(v);
  }
  w.f64(s.s0);
  w.u64(m.seed);
  w.u32(m.threads);
  w.u64(m.iteration);
  if (m.version >= 2) {
    w.f64(m.held_out_completion);
    w.f64(m.held_out_interpolation);
    w.i32(m.held_out_gap);
  }
  if (m.version >= 3) w.i32(s.placement_nodes);
  if (s.kind == ModelKind::mesh) {
    w.u32(static_cast<std::uint32_t>(m.triangles.size()));
    for (Eigen::Index i = 0; i < m.rest.size(); ++i) w.f64(m.rest.data()[i]);
    for (const auto& t : m.triangles) {
      for (int c : t) w.u32(static_cast<std::uint32_t>(c));
    }
  } else {
    for (const std::string& n : m.joint_names) w.name(n);
  }
  w.u32(static_cast<std::uint32_t>(m.low.size()));
  for (double v : m.low) w.f64(v);
  for (double v : m.high) w.f64(v);
  w.arrays(m.parameters);
  w.arrays(m.optimiser);
  w.u32(static_cast<std::uint32_t>(crc32(0L, w.bytes.data(), static_cast<uInt>(w.bytes.size()))));
  return std::move(w.bytes);
}

void write_model_file(const std::string& file, const ModelFile& model) {
  const std::vector<std::uint8_t> bytes = model_file_bytes(model);
  // Written beside and renamed, so that an interrupted save (a checkpoint
  // during training) never leaves a half file under the name; the rename
  // must not replace a device or a folder given as the file.
  check_replaceable_file(file);
  const std::string partial = file + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(file + ": cannot write");
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error(file + ": write failed");
  }
  if (std::rename(partial.c_str(), file.c_str()) != 0) {
    throw std::runtime_error(file + ": cannot rename " + partial + " to it");
  }
}

ModelFile parse_model_file(const std::vector<std::uint8_t>& bytes, const std::string& file) {
  const detail::ByteView in(bytes, file);
  ModelReader r{in};
  in.need(0, 8, 1, "header", "magic");
  if (std::memcmp(bytes.data(), kModelFileMagic, 8) != 0) {
    detail::fail(file, "header", "not an animrt sequence model (magic is not ANSEQNN)");
  }
  r.at = 8;
  ModelFile m;
  const std::uint32_t version = r.u32("header", "version");
  m.version = version;
  if (version < 1 || version > kModelFileVersion) {
    detail::fail(file, "header",
                 "version " + std::to_string(version) + ", this build reads versions 1 to " +
                     std::to_string(kModelFileVersion));
  }
  const std::uint32_t kind = r.u32("header", "kind");
  if (kind != 1 && kind != 2) {
    detail::fail(file, "header", "kind " + std::to_string(kind) + " (1 mesh, 2 joints)");
  }
  NetShape& s = m.shape;
  s.kind = static_cast<ModelKind>(kind);
  const bool mesh = s.kind == ModelKind::mesh;
  s.vertex_count = r.bounded("vertex count", mesh ? 3 : 0, mesh ? 1000000 : 0);
  s.joint_count = r.bounded("joint count", mesh ? 0 : 1, mesh ? 0 : 1024);
  s.conv_layers = r.bounded("convolution layers", 1, 8);
  s.channels = r.bounded("channels", 1, 256);
  s.dense_width = r.bounded("dense width", 1, 4096);
  s.latent = r.bounded("latent size", 1, 4096);
  s.hidden = r.bounded("hidden units", 1, 4096);
  s.lstm_layers = r.bounded("LSTM layers", 1, 8);
  s.window = r.bounded("window", 2, 4096);
  s.stride = r.bounded("stride", 1, 16);
  s.s0 = r.f64("shape", "s0");
  if (!std::isfinite(s.s0) || std::abs(s.s0) > 10.0) {
    detail::fail(file, "shape", "s0 is " + std::to_string(s.s0) + ", expected -10..10");
  }
  m.seed = r.u64("header", "seed");
  m.threads = r.u32("header", "threads");
  m.iteration = r.u64("header", "iteration");
  if (version >= 2) {
    m.held_out_completion = r.f64("header", "held-out completion");
    m.held_out_interpolation = r.f64("header", "held-out interpolation");
    m.held_out_gap = r.bounded("held-out gap", 0, 1000000);
    if (!std::isfinite(m.held_out_completion) || !std::isfinite(m.held_out_interpolation)) {
      detail::fail(file, "header", "the held-out measurement is not finite");
    }
  }
  if (version >= 3) {
    // A piece has 3 vertices or more, so 3 numbers per piece take fewer
    // nodes than there are vertices.
    s.placement_nodes = r.bounded("placement nodes", 0, mesh ? s.vertex_count : 0);
  }
  if (mesh) {
    const std::uint32_t triangles = r.u32("header", "triangle count");
    const auto v = static_cast<std::uint64_t>(s.vertex_count);
    in.need(r.at, 3 * v, 8, "header", "template positions");
    m.rest.resize(3, static_cast<Eigen::Index>(v));
    for (Eigen::Index i = 0; i < m.rest.size(); ++i) {
      m.rest.data()[i] = r.f64("header", "template positions");
      if (!std::isfinite(m.rest.data()[i])) {
        detail::fail(file, "vertex " + std::to_string(i / 3), "template position is not finite");
      }
    }
    in.need(r.at, triangles, 12, "header", "triangles");
    m.triangles.resize(triangles);
    for (std::uint32_t t = 0; t < triangles; ++t) {
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t idx = r.u32("triangle", "triangle");
        if (idx >= v) {
          detail::fail(file, "triangle " + std::to_string(t),
                       "vertex index " + std::to_string(idx) + " out of range (" +
                           std::to_string(v) + " vertices)");
        }
        m.triangles[t][static_cast<std::size_t>(c)] = static_cast<int>(idx);
      }
    }
  } else {
    for (int j = 0; j < s.joint_count; ++j) {
      m.joint_names.push_back(r.name("joint " + std::to_string(j), "joint name"));
    }
  }
  const std::uint32_t dims = r.u32("mapping", "mapping size");
  if (dims != static_cast<std::uint32_t>(s.input_dims())) {
    detail::fail(
        file, "mapping",
        std::to_string(dims) + " dimensions, the shape has " + std::to_string(s.input_dims()));
  }
  in.need(r.at, 2 * std::uint64_t{dims}, 8, "mapping", "feature mapping");
  m.low.resize(dims);
  m.high.resize(dims);
  for (double& v : m.low) v = r.f64("mapping", "low");
  for (double& v : m.high) v = r.f64("mapping", "high");
  for (std::uint32_t i = 0; i < dims; ++i) {
    if (!std::isfinite(m.low[i]) || !std::isfinite(m.high[i]) || m.high[i] < m.low[i]) {
      detail::fail(file, "mapping",
                   "dimension " + std::to_string(i) + " has low " + std::to_string(m.low[i]) +
                       " and high " + std::to_string(m.high[i]));
    }
  }
  m.parameters = r.arrays("parameter");
  m.optimiser = r.arrays("optimiser");
  if (r.at + 4 != bytes.size()) {
    if (r.at + 4 > bytes.size()) {
      detail::fail(file, "checksum", "file is truncated: the checksum is missing");
    }
    detail::fail(file, "checksum",
                 std::to_string(bytes.size() - r.at - 4) + " bytes after the last section");
  }
  const std::uint32_t stored = in.u32(r.at);
  const auto computed =
      static_cast<std::uint32_t>(crc32(0L, bytes.data(), static_cast<uInt>(bytes.size() - 4)));
  if (stored != computed) {
    detail::fail(file, "checksum", "CRC-32 does not match: the file is corrupt");
  }
  return m;
}

ModelFile read_model_file(const std::string& file) {
  return parse_model_file(detail::read_file_bytes(file, detail::kMaxModelFileBytes), file);
}

std::string interpolation_warning(const ModelFile& m, const std::string& file) {
  if (m.held_out_completion < 0 || m.held_out_interpolation < 0) {
    return "warning: " + file +
           ": never measured against linear interpolation on held-out data (trained by an older "
           "build, or no held-out piece was long enough); it may complete worse than a straight "
           "line";
  }
  if (m.held_out_completion < m.held_out_interpolation) return "";
  char numbers[160];
  std::snprintf(numbers, sizeof numbers,
                " (%.2f %% against %.2f %% for linear interpolation, %d-frame gaps, after %llu "
                "iterations)",
                100.0 * m.held_out_completion, 100.0 * m.held_out_interpolation, m.held_out_gap,
                static_cast<unsigned long long>(m.iteration));
  return "warning: " + file + ": never measured better than linear interpolation on held-out data" +
         numbers + "; train it longer";
}

void check_model_mesh(const ModelFile& model, const std::string& file, int vertex_count,
                      const std::vector<std::array<int, 3>>& triangles) {
  if (model.shape.kind != ModelKind::mesh) {
    detail::fail(file, "kind",
                 "a joint-space model (" + std::to_string(model.shape.joint_count) +
                     " joints), the data is a mesh of " + std::to_string(vertex_count) +
                     " vertices");
  }
  if (model.shape.vertex_count != vertex_count) {
    detail::fail(file, "mesh",
                 "trained on a mesh of " + std::to_string(model.shape.vertex_count) +
                     " vertices, the data has " + std::to_string(vertex_count));
  }
  if (connectivity_hash(vertex_count, model.triangles) !=
      connectivity_hash(vertex_count, triangles)) {
    detail::fail(file, "mesh",
                 "trained on another connectivity (" + std::to_string(model.triangles.size()) +
                     " triangles, the data has " + std::to_string(triangles.size()) +
                     (model.triangles.size() == triangles.size() ? ", ordered differently)" : ")"));
  }
}

void check_model_joints(const ModelFile& model, const std::string& file,
                        const std::vector<std::string>& joint_names) {
  if (model.shape.kind != ModelKind::joints) {
    detail::fail(file, "kind",
                 "a mesh model (" + std::to_string(model.shape.vertex_count) +
                     " vertices), the data is " + std::to_string(joint_names.size()) + " joints");
  }
  if (model.joint_names == joint_names) return;
  std::string missing, extra;
  for (const std::string& n : model.joint_names) {
    if (std::find(joint_names.begin(), joint_names.end(), n) == joint_names.end()) {
      missing += (missing.empty() ? "" : ", ") + n;
    }
  }
  for (const std::string& n : joint_names) {
    if (std::find(model.joint_names.begin(), model.joint_names.end(), n) ==
        model.joint_names.end()) {
      extra += (extra.empty() ? "" : ", ") + n;
    }
  }
  std::string what = "trained on another joint set:";
  if (!missing.empty()) what += " the data lacks " + missing + ";";
  if (!extra.empty()) what += " the model lacks " + extra + ";";
  if (missing.empty() && extra.empty()) what += " same joints in another order;";
  what.pop_back();
  detail::fail(file, "joints", what);
}

}  // namespace animrt::seqnet
