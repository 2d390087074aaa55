// Writing mesh sequences as OBJ files (see mesh_io.hpp): vertices with nine
// significant digits (what the formats read in carry, and a round trip in
// metres keeps sub-micrometre detail), faces 1-based as OBJ counts.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "animrt/controllers/seqnet/mesh_io.hpp"

namespace animrt::seqnet {
namespace {

namespace fs = std::filesystem;

// Digits in frame names: at least four, more when the sequence is longer, so
// that name order is frame order.
int name_width(int frames) {
  int width = 4;
  for (int limit = 10000; frames > limit && width < 9; limit *= 10) ++width;
  return width;
}

std::string frame_name(int frame, int width) {
  std::string digits = std::to_string(frame);
  if (static_cast<int>(digits.size()) < width)
    digits.insert(0, static_cast<std::size_t>(width) - digits.size(), '0');
  return "frame_" + digits + ".obj";
}

// frame_<digits>.obj
bool is_frame_name(const std::string& name) {
  const std::string head = "frame_", tail = ".obj";
  if (name.size() <= head.size() + tail.size()) return false;
  if (name.compare(0, head.size(), head) != 0) return false;
  if (name.compare(name.size() - tail.size(), tail.size(), tail) != 0) return false;
  for (std::size_t i = head.size(); i < name.size() - tail.size(); ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  return true;
}

void check(const MeshSequence& sequence) {
  const long vertices = sequence.vertex_count();
  for (std::size_t f = 0; f < sequence.frames.size(); ++f) {
    if (sequence.frames[f].cols() != vertices) {
      throw std::invalid_argument("mesh sequence: frame " + std::to_string(f) + " has " +
                                  std::to_string(sequence.frames[f].cols()) +
                                  " vertices, frame 0 has " + std::to_string(vertices));
    }
  }
  for (std::size_t t = 0; t < sequence.triangles.size(); ++t) {
    for (int v : sequence.triangles[t]) {
      if (v < 0 || v >= vertices) {
        throw std::invalid_argument("mesh sequence: triangle " + std::to_string(t) +
                                    " names vertex " + std::to_string(v) + " of " +
                                    std::to_string(vertices));
      }
    }
  }
}

void write_frame(const std::string& file, const MeshSequence& sequence, int frame) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + file);
  const Positions& p = sequence.frames[static_cast<std::size_t>(frame)];
  std::string text;
  text.reserve(static_cast<std::size_t>(p.cols()) * 40 + sequence.triangles.size() * 24 + 64);
  char line[128];
  std::snprintf(line, sizeof line, "# frame %d of %d: %ld vertices, %zu triangles\n", frame,
                sequence.frame_count(), static_cast<long>(p.cols()), sequence.triangles.size());
  text += line;
  for (Eigen::Index v = 0; v < p.cols(); ++v) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p(0, v), p(1, v), p(2, v));
    text += line;
  }
  for (const auto& t : sequence.triangles) {
    std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    text += line;
  }
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + file);
}

}  // namespace

void write_obj(const std::string& file, const MeshSequence& sequence, int frame) {
  if (frame < 0 || frame >= sequence.frame_count()) {
    throw std::out_of_range("write_obj: frame " + std::to_string(frame) + " of a sequence of " +
                            std::to_string(sequence.frame_count()) + " frames");
  }
  check(sequence);
  write_frame(file, sequence, frame);
}

void write_obj_sequence(const std::string& folder, const MeshSequence& sequence) {
  check(sequence);
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec || !fs::is_directory(folder)) {
    throw std::runtime_error("cannot create folder " + folder + ": " + ec.message());
  }
  // Frames of an earlier, longer sequence would be read back as part of this
  // one: remove every frame file first.
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && is_frame_name(entry.path().filename().string()))
      stale.push_back(entry.path());
  }
  for (const auto& path : stale) fs::remove(path);
  const int width = name_width(sequence.frame_count());
  for (int f = 0; f < sequence.frame_count(); ++f) {
    write_frame((fs::path(folder) / frame_name(f, width)).string(), sequence, f);
  }
}

}  // namespace animrt::seqnet
