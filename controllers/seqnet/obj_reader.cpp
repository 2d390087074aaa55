// OBJ files and folders of them. Only `v` and `f` lines matter: texture
// coordinates and normals are ignored, polygons are fan-triangulated, face
// indices are 1-based or negative (relative to the vertices read so far).

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "animrt/controllers/seqnet/mesh_io.hpp"
#include "file_bytes.hpp"
#include "mesh_checks.hpp"

namespace animrt::seqnet {
namespace {

[[noreturn]] void obj_fail(const std::string& file, int line, int column, const std::string& key,
                           const std::string& message) {
  throw InputError(Location{file, line, column}, key, message);
}

bool parse_double(std::string_view token, double& out) {
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
  return ec == std::errc() && end == token.data() + token.size();
}

// Splits a line into tokens with their 1-based columns.
std::vector<std::pair<std::string_view, int>> tokens_of(std::string_view line) {
  std::vector<std::pair<std::string_view, int>> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i >= line.size() || line[i] == '#') break;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r' &&
           line[i] != '#') {
      ++i;
    }
    out.emplace_back(line.substr(start, i - start), static_cast<int>(start) + 1);
  }
  return out;
}

// Limits of one OBJ frame: the sequence model's own bound on vertices, and
// two triangles a vertex. A vertex line of 8 bytes becomes 24 in memory and
// a face line 12 plus its edges in the checks, so a file within the size
// limit could otherwise ask for several times its size.
constexpr std::size_t kMaxObjVertices = 1000000;
constexpr std::size_t kMaxObjTriangles = 2000000;

// How many lines of `text` are vertex lines ("v" then a blank), counted
// before any is parsed so that the positions are sized once.
std::size_t count_vertex_lines(std::string_view text) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::size_t count = 0;
  std::size_t at = 0;
  while (at < text.size()) {
    while (at < text.size() && blank(text[at])) ++at;
    if (at < text.size() && text[at] == 'v' &&
        (at + 1 == text.size() || blank(text[at + 1]) || text[at + 1] == '#' ||
         text[at + 1] == '\n'))
      ++count;
    const std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) break;
    at = end + 1;
  }
  return count;
}

// The vertices and triangles of one file, unchecked beyond syntax.
MeshSequence parse_obj(const std::string& file) {
  const std::vector<std::uint8_t> bytes = detail::read_file_bytes(file);
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::size_t vertex_lines = count_vertex_lines(text);
  if (vertex_lines > kMaxObjVertices) {
    detail::fail(file, "v",
                 std::to_string(vertex_lines) + " vertices, more than the " +
                     std::to_string(kMaxObjVertices) + " a frame may have");
  }
  Positions frame(3, static_cast<Eigen::Index>(vertex_lines));
  std::size_t vertices = 0;
  MeshSequence out;
  out.source = file;
  std::size_t at = 0;
  int line_no = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    const auto tokens = tokens_of(line);
    if (tokens.empty()) continue;
    const std::string_view kind = tokens[0].first;
    if (kind == "v") {
      if (tokens.size() < 4) obj_fail(file, line_no, 1, "v", "needs x y z");
      // The count above sees every line tokens_of reads as "v"; a mismatch
      // would be a bug here, never a reason to write past the positions.
      if (vertices >= vertex_lines) obj_fail(file, line_no, 1, "v", "vertex lines miscounted");
      for (int k = 0; k < 3; ++k) {
        double& p = frame(k, static_cast<Eigen::Index>(vertices));
        if (!parse_double(tokens[k + 1].first, p) || !std::isfinite(p)) {
          obj_fail(file, line_no, tokens[k + 1].second, "v",
                   "expected a number, found " + quote(tokens[k + 1].first));
        }
      }
      ++vertices;
    } else if (kind == "f") {
      if (tokens.size() < 4) obj_fail(file, line_no, 1, "f", "needs at least three vertices");
      std::vector<int> corners;
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        const std::string_view token = tokens[k].first;
        const std::string_view first = token.substr(0, token.find('/'));
        long long index = 0;
        const auto [stop, ec] = std::from_chars(first.data(), first.data() + first.size(), index);
        const long long count = static_cast<long long>(vertices);
        if (ec != std::errc() || stop != first.data() + first.size() || index == 0) {
          obj_fail(file, line_no, tokens[k].second, "f",
                   "expected a vertex index, found " + quote(token));
        }
        const long long resolved = index > 0 ? index - 1 : count + index;
        if (resolved < 0 || resolved >= count) {
          obj_fail(file, line_no, tokens[k].second, "f",
                   "vertex index " + std::to_string(index) + " is out of range (" +
                       std::to_string(count) + " vertices so far)");
        }
        corners.push_back(static_cast<int>(resolved));
      }
      if (out.triangles.size() + corners.size() - 2 > kMaxObjTriangles) {
        obj_fail(
            file, line_no, 1, "f",
            "more than the " + std::to_string(kMaxObjTriangles) + " triangles a frame may have");
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        out.triangles.push_back({corners[0], corners[k], corners[k + 1]});
      }
    }
    // vt, vn, g, o, s, usemtl, mtllib and the rest carry nothing we use.
  }
  out.frames.push_back(std::move(frame));
  return out;
}

}  // namespace

MeshSequence read_obj(const std::string& file) {
  MeshSequence out = parse_obj(file);
  detail::validate_mesh(out, file);
  return out;
}

MeshSequence read_obj_sequence(const std::string& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) detail::fail(folder, "", "is not a folder");
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string path = entry.path().string();
    if (detail::extension_without_gz(path) != ".obj") continue;
    // A frame that is a FIFO, a device or a link to one is refused by name:
    // skipping it would drop a frame from the sequence without a word.
    if (const std::string problem = input_file_problem(path); !problem.empty())
      detail::fail(path, "", problem == kFileMissing ? "is a broken link" : problem);
    files.push_back(path);
  }
  if (ec) detail::fail(folder, "", "cannot list the folder (" + ec.message() + ")");
  if (files.empty()) detail::fail(folder, "", "holds no .obj files");
  std::sort(files.begin(), files.end());
  MeshSequence out = read_obj(files.front());
  out.source = folder;
  for (std::size_t f = 1; f < files.size(); ++f) {
    const std::string key = "frame " + std::to_string(f);
    MeshSequence next;
    try {
      next = parse_obj(files[f]);
    } catch (const InputError& e) {
      throw InputError(e.where(), e.key().empty() ? key : key + ": " + e.key(), e.message());
    }
    if (next.vertex_count() != out.vertex_count()) {
      detail::fail(files[f], key,
                   std::to_string(next.vertex_count()) + " vertices, " + files.front() + " has " +
                       std::to_string(out.vertex_count()));
    }
    if (next.triangles != out.triangles) {
      std::size_t t = 0;
      while (t < next.triangles.size() && t < out.triangles.size() &&
             next.triangles[t] == out.triangles[t]) {
        ++t;
      }
      detail::fail(files[f], key,
                   "connectivity differs from " + files.front() + " (first at triangle " +
                       std::to_string(t) + ")");
    }
    if (!next.frames.front().allFinite()) detail::fail(files[f], key, "a position is not finite");
    out.frames.push_back(std::move(next.frames.front()));
  }
  return out;
}

MeshSequence read_mesh_pose(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec) || detail::extension_without_gz(path) != ".obj")
    return read_mesh_sequence(path);
  MeshSequence out = parse_obj(path);
  detail::validate_mesh(out, path, true);
  return out;
}

MeshSequence read_mesh_sequence(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return read_obj_sequence(path);
  const std::string ext = detail::extension_without_gz(path);
  if (ext == ".obj") return read_obj(path);
  if (ext == ".md2") return read_md2(path);
  if (ext == ".md3") return read_md3(path);
  detail::fail(path, "",
               "unknown mesh format " + quote(ext) +
                   " (expected .obj, .md2, .md3, optionally .gz, or a folder of .obj)");
}

}  // namespace animrt::seqnet
