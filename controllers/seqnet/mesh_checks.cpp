#include "mesh_checks.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "animrt/core/yaml_doc.hpp"
#include "file_bytes.hpp"

namespace animrt::seqnet::detail {
namespace {

// The largest vertex coordinate a mesh may have, in its own units.
constexpr double kMaxVertexCoordinate = 1e9;

}  // namespace

void merge_coincident(MeshSequence& sequence, const std::vector<int>& group) {
  const int v = sequence.vertex_count();
  const int frames = sequence.frame_count();
  std::vector<int> order(static_cast<std::size_t>(v));
  std::iota(order.begin(), order.end(), 0);
  // Lexicographic over (group, frame 0 xyz, frame 1 xyz, ...), ties by index.
  auto less = [&](int a, int b) {
    if (group[a] != group[b]) return group[a] < group[b];
    for (int f = 0; f < frames; ++f) {
      for (int k = 0; k < 3; ++k) {
        const double x = sequence.frames[f](k, a);
        const double y = sequence.frames[f](k, b);
        if (x != y) return x < y;
      }
    }
    return a < b;
  };
  auto same = [&](int a, int b) {
    if (group[a] != group[b]) return false;
    for (int f = 0; f < frames; ++f) {
      if (sequence.frames[f].col(a) != sequence.frames[f].col(b)) return false;
    }
    return true;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<int> representative(static_cast<std::size_t>(v));
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j < order.size() && same(order[i], order[j])) ++j;
    for (std::size_t k = i; k < j; ++k) representative[order[k]] = order[i];  // lowest index
    i = j;
  }
  std::vector<int> new_index(static_cast<std::size_t>(v), -1);
  int kept = 0;
  for (int i = 0; i < v; ++i) {
    if (representative[i] == i) new_index[i] = kept++;
  }
  if (kept == v) return;
  for (auto& frame : sequence.frames) {
    Positions merged(3, kept);
    for (int i = 0; i < v; ++i) {
      if (new_index[i] >= 0) merged.col(new_index[i]) = frame.col(i);
    }
    frame = std::move(merged);
  }
  for (auto& t : sequence.triangles) {
    for (int& corner : t) corner = new_index[representative[corner]];
  }
}

int detach_non_manifold(MeshSequence& sequence) {
  std::map<std::pair<int, int>, int> edge_use;
  int detached = 0;
  for (auto& tri : sequence.triangles) {
    bool over = false;
    for (int k = 0; k < 3; ++k) {
      const auto e = std::minmax(tri[k], tri[(k + 1) % 3]);
      if (edge_use[{e.first, e.second}] >= 2) over = true;
    }
    if (!over) {
      for (int k = 0; k < 3; ++k) {
        const auto e = std::minmax(tri[k], tri[(k + 1) % 3]);
        ++edge_use[{e.first, e.second}];
      }
      continue;
    }
    for (int& corner : tri) {
      const int copy = sequence.vertex_count();
      for (auto& frame : sequence.frames) {
        frame.conservativeResize(3, copy + 1);
        frame.col(copy) = frame.col(corner);
      }
      corner = copy;
    }
    ++detached;
  }
  return detached;
}

void validate_mesh(const MeshSequence& sequence, const std::string& file, bool pose) {
  if (sequence.frames.empty()) fail(file, "", "has no frames");
  if (sequence.triangles.empty()) fail(file, "", "has no triangles");
  const int v = sequence.vertex_count();
  for (int f = 0; f < sequence.frame_count(); ++f) {
    const std::string key = "frame " + std::to_string(f);
    if (sequence.frames[f].cols() != v) {
      fail(file, key,
           std::to_string(sequence.frames[f].cols()) + " vertices, frame 0 has " +
               std::to_string(v));
    }
    if (!sequence.frames[f].allFinite()) fail(file, key, "a vertex position is not finite");
    // Squared in the features, 1e308 overflowed to a round trip of NaN.
    if (const double far = sequence.frames[f].cwiseAbs().maxCoeff(); far > kMaxVertexCoordinate) {
      fail(file, key,
           "a vertex coordinate of " + format_number(far) +
               ", beyond 1e9 (a kilometre in micrometres; no mesh is that large)");
    }
  }
  std::map<std::pair<int, int>, int> edge_use;
  for (std::size_t t = 0; t < sequence.triangles.size(); ++t) {
    const auto& tri = sequence.triangles[t];
    const std::string which = "triangle " + std::to_string(t);
    for (int corner : tri) {
      if (corner < 0 || corner >= v) {
        fail(file, "frame 0",
             which + " uses vertex " + std::to_string(corner) + ", the mesh has " +
                 std::to_string(v));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      fail(file, "frame 0", which + " repeats a vertex (degenerate)");
    }
    for (int k = 0; k < 3; ++k) {
      const int a = std::min(tri[k], tri[(k + 1) % 3]);
      const int b = std::max(tri[k], tri[(k + 1) % 3]);
      if (++edge_use[{a, b}] > 2) {
        fail(file, "frame 0",
             "edge " + std::to_string(a) + "-" + std::to_string(b) +
                 " is shared by more than two triangles (non-manifold), the third is " + which);
      }
    }
  }
  // Zero area is judged in the first frame only: it is the template the
  // deformation features are measured against. Later frames may legitimately
  // flatten a triangle (quantised game formats do), and so may a key or an
  // initial frame, which is measured against a model's template.
  if (pose) return;
  const Positions& rest = sequence.frames.front();
  const double diagonal = (rest.rowwise().maxCoeff() - rest.rowwise().minCoeff()).norm();
  const double tiny = 1e-14 * diagonal * diagonal;
  for (std::size_t t = 0; t < sequence.triangles.size(); ++t) {
    const auto& tri = sequence.triangles[t];
    const Eigen::Vector3d a = rest.col(tri[0]);
    const double area2 = (rest.col(tri[1]) - a).cross(rest.col(tri[2]) - a).norm();
    if (!(area2 > tiny)) fail(file, "frame 0", "triangle " + std::to_string(t) + " has zero area");
  }
}

}  // namespace animrt::seqnet::detail
