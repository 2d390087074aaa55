// Components and the manifold checks of a triangle mesh (see triangle_mesh.hpp).

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "animrt/learn/seq_corpus/triangle_mesh.hpp"

namespace animrt::learn::seq_corpus {
namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int find(int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  }
  void join(int a, int b) { parent[static_cast<std::size_t>(find(a))] = find(b); }
};

// Triangle components through shared vertices: the root of each vertex.
UnionFind vertex_components(const TriangleMesh& mesh) {
  UnionFind uf(static_cast<int>(mesh.vertices.cols()));
  for (const auto& t : mesh.triangles) {
    uf.join(t[0], t[1]);
    uf.join(t[1], t[2]);
  }
  return uf;
}

}  // namespace

TriangleMesh largest_component(const TriangleMesh& mesh) {
  UnionFind uf = vertex_components(mesh);
  std::vector<int> size(static_cast<std::size_t>(mesh.vertices.cols()), 0);
  for (const auto& t : mesh.triangles) ++size[static_cast<std::size_t>(uf.find(t[0]))];
  int best = -1;
  for (std::size_t v = 0; v < size.size(); ++v) {
    if (best < 0 || size[v] > size[static_cast<std::size_t>(best)]) best = static_cast<int>(v);
  }
  TriangleMesh out;
  if (best < 0) return out;
  std::vector<int> renumber(size.size(), -1);
  std::vector<int> kept;
  for (const auto& t : mesh.triangles) {
    if (uf.find(t[0]) != best) continue;
    std::array<int, 3> nt{};
    for (int c = 0; c < 3; ++c) {
      int& r = renumber[static_cast<std::size_t>(t[static_cast<std::size_t>(c)])];
      if (r < 0) {
        r = static_cast<int>(kept.size());
        kept.push_back(t[static_cast<std::size_t>(c)]);
      }
      nt[static_cast<std::size_t>(c)] = r;
    }
    out.triangles.push_back(nt);
  }
  out.vertices.resize(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t v = 0; v < kept.size(); ++v)
    out.vertices.col(static_cast<Eigen::Index>(v)) = mesh.vertices.col(kept[v]);
  return out;
}

MeshReport check_mesh(const TriangleMesh& mesh, double min_area) {
  MeshReport r;
  r.vertices = static_cast<int>(mesh.vertices.cols());
  r.triangles = static_cast<int>(mesh.triangles.size());
  r.min_area = mesh.triangles.empty() ? 0.0 : 1e300;
  r.min_angle_deg = mesh.triangles.empty() ? 0.0 : 180.0;
  std::vector<char> used(static_cast<std::size_t>(r.vertices), 0);
  // Directed edges, sorted by their undirected key.
  struct Edge {
    int lo, hi;
    bool forward;  // lo -> hi
  };
  std::vector<Edge> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    bool bad = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    for (int c = 0; c < 3; ++c) {
      const int a = t[static_cast<std::size_t>(c)], b = t[static_cast<std::size_t>((c + 1) % 3)];
      if (a < 0 || a >= r.vertices) bad = true;
      if (a >= 0 && a < r.vertices) used[static_cast<std::size_t>(a)] = 1;
      edges.push_back({std::min(a, b), std::max(a, b), a < b});
    }
    if (bad) {
      ++r.degenerate;
      continue;
    }
    const Eigen::Vector3d p0 = mesh.vertices.col(t[0]), p1 = mesh.vertices.col(t[1]),
                          p2 = mesh.vertices.col(t[2]);
    const double area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    r.min_area = std::min(r.min_area, area);
    if (!(area >= min_area)) ++r.degenerate;
    const std::array<Eigen::Vector3d, 3> p{p0, p1, p2};
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d u =
          p[static_cast<std::size_t>((c + 1) % 3)] - p[static_cast<std::size_t>(c)];
      const Eigen::Vector3d w =
          p[static_cast<std::size_t>((c + 2) % 3)] - p[static_cast<std::size_t>(c)];
      const double angle = std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI;
      r.min_angle_deg = std::min(r.min_angle_deg, angle);
    }
  }
  if (r.degenerate > 0) return r;  // the checks below assume valid indices
  for (char u : used) r.unused_vertices += u ? 0 : 1;
  std::sort(edges.begin(), edges.end(),
            [](const Edge& a, const Edge& b) { return a.lo != b.lo ? a.lo < b.lo : a.hi < b.hi; });
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    int forward = 0;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) {
      forward += edges[j].forward ? 1 : 0;
      ++j;
    }
    const std::size_t uses = j - i;
    ++r.edges;
    if (uses == 1) ++r.boundary_edges;
    if (uses > 2) ++r.nonmanifold_edges;
    if (uses == 2 && forward != 1) ++r.misoriented_edges;
    i = j;
  }
  // Around a manifold vertex the opposite edges of its triangles form one
  // cycle.
  std::vector<std::vector<std::pair<int, int>>> link(static_cast<std::size_t>(r.vertices));
  for (const auto& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) {
      link[static_cast<std::size_t>(t[static_cast<std::size_t>(c)])].push_back(
          {t[static_cast<std::size_t>((c + 1) % 3)], t[static_cast<std::size_t>((c + 2) % 3)]});
    }
  }
  for (auto& l : link) {
    if (l.empty()) continue;
    std::sort(l.begin(), l.end());
    bool ok = true;
    for (std::size_t i = 1; i < l.size(); ++i) ok = ok && l[i].first != l[i - 1].first;
    std::size_t steps = 0;
    int at = l.front().first;
    while (ok) {
      const auto it = std::lower_bound(l.begin(), l.end(), std::make_pair(at, -1));
      if (it == l.end() || it->first != at) {
        ok = false;
        break;
      }
      at = it->second;
      ++steps;
      if (at == l.front().first || steps > l.size()) break;
    }
    if (!ok || steps != l.size()) ++r.nonmanifold_vertices;
  }
  UnionFind uf = vertex_components(mesh);
  for (int v = 0; v < r.vertices; ++v) r.components += uf.find(v) == v ? 1 : 0;
  return r;
}

double enclosed_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const auto& t : mesh.triangles) {
    six_v += mesh.vertices.col(t[0]).dot(mesh.vertices.col(t[1]).cross(mesh.vertices.col(t[2])));
  }
  return six_v / 6.0;
}

}  // namespace animrt::learn::seq_corpus
