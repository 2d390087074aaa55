// Marching tetrahedra (see triangle_mesh.hpp).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

#include "animrt/learn/seq_corpus/triangle_mesh.hpp"

namespace animrt::learn::seq_corpus {
namespace {

// Crossings are kept this share of an edge away from its ends.
constexpr double kEdgeMargin = 0.1;

// The six orders of the axes: each is one tetrahedron of the cube, from
// corner (0,0,0) one axis at a time to corner (1,1,1).
constexpr std::array<std::array<int, 3>, 6> kAxisOrders = {
    {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};

}  // namespace

TriangleMesh marching_tetrahedra(const std::function<double(const Eigen::Vector3d&)>& field,
                                 const Eigen::AlignedBox3d& box, double step) {
  if (!(step > 0.0) || box.isEmpty()) throw std::invalid_argument("marching_tetrahedra: bad grid");
  std::array<long, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = static_cast<long>(std::ceil(box.sizes()[a] / step)) + 1;
  if (n[0] * n[1] * n[2] > 50'000'000L)
    throw std::invalid_argument("marching_tetrahedra: grid too fine");
  const auto node = [&](long i, long j, long k) { return (k * n[1] + j) * n[0] + i; };
  const auto where = [&](long i, long j, long k) {
    return Eigen::Vector3d(box.min().x() + static_cast<double>(i) * step,
                           box.min().y() + static_cast<double>(j) * step,
                           box.min().z() + static_cast<double>(k) * step);
  };
  std::vector<double> f(static_cast<std::size_t>(n[0] * n[1] * n[2]));
  for (long k = 0; k < n[2]; ++k)
    for (long j = 0; j < n[1]; ++j)
      for (long i = 0; i < n[0]; ++i)
        f[static_cast<std::size_t>(node(i, j, k))] = field(where(i, j, k));

  TriangleMesh out;
  std::vector<Eigen::Vector3d> vertices;
  // Grid edge (lower node, direction 1..7 as bits x, y, z) -> vertex.
  std::unordered_map<std::int64_t, int> edge_vertex;
  struct Corner {
    long i, j, k;
    double value;
  };
  const auto vertex_on = [&](const Corner& a, const Corner& b) {
    // Corners come in path order, so b - a is a 0/1 step from a.
    const int dir = static_cast<int>((b.i - a.i) | ((b.j - a.j) << 1) | ((b.k - a.k) << 2));
    const std::int64_t key = node(a.i, a.j, a.k) * 8 + dir;
    const auto [it, added] = edge_vertex.try_emplace(key, static_cast<int>(vertices.size()));
    if (added) {
      const double t = std::clamp(a.value / (a.value - b.value), kEdgeMargin, 1.0 - kEdgeMargin);
      vertices.push_back(where(a.i, a.j, a.k) + t * (where(b.i, b.j, b.k) - where(a.i, a.j, a.k)));
    }
    return it->second;
  };
  for (long k = 0; k + 1 < n[2]; ++k) {
    for (long j = 0; j + 1 < n[1]; ++j) {
      for (long i = 0; i + 1 < n[0]; ++i) {
        for (const auto& order : kAxisOrders) {
          std::array<Corner, 4> c{};
          std::array<long, 3> at{i, j, k};
          for (int m = 0; m < 4; ++m) {
            if (m > 0) ++at[static_cast<std::size_t>(order[static_cast<std::size_t>(m - 1)])];
            c[static_cast<std::size_t>(m)] = {
                at[0], at[1], at[2], f[static_cast<std::size_t>(node(at[0], at[1], at[2]))]};
          }
          int inside_mask = 0;
          for (int m = 0; m < 4; ++m)
            inside_mask |= (c[static_cast<std::size_t>(m)].value < 0.0) << m;
          if (inside_mask == 0 || inside_mask == 15) continue;
          std::array<int, 4> in{}, outside{};
          int ni = 0, no = 0;
          for (int m = 0; m < 4; ++m) ((inside_mask >> m) & 1 ? in[ni++] : outside[no++]) = m;
          const auto edge = [&](int a, int b) {
            // Path order: the lower corner first.
            return a < b
                       ? vertex_on(c[static_cast<std::size_t>(a)], c[static_cast<std::size_t>(b)])
                       : vertex_on(c[static_cast<std::size_t>(b)], c[static_cast<std::size_t>(a)]);
          };
          // Each triangle with a corner of the tetrahedron that lies off its
          // plane (two of its vertices are on that corner's edges): facing
          // away from an inside corner, towards an outside one.
          struct Face {
            std::array<int, 3> v;
            int corner;
          };
          std::array<Face, 2> faces{};
          int count = 0;
          if (ni == 1 || no == 1) {
            const int lone = ni == 1 ? in[0] : outside[0];
            const auto& others = ni == 1 ? outside : in;
            faces[count++] = {{edge(lone, others[0]), edge(lone, others[1]), edge(lone, others[2])},
                              lone};
          } else {
            const int a = in[0], b = in[1], cc = outside[0], d = outside[1];
            const int ac = edge(a, cc), ad = edge(a, d), bd = edge(b, d), bc = edge(b, cc);
            faces[count++] = {{ac, ad, bd}, a};
            faces[count++] = {{ac, bd, bc}, b};
          }
          for (int t = 0; t < count; ++t) {
            auto& [tri, corner] = faces[static_cast<std::size_t>(t)];
            const Eigen::Vector3d& p0 = vertices[static_cast<std::size_t>(tri[0])];
            const Eigen::Vector3d normal =
                (vertices[static_cast<std::size_t>(tri[1])] - p0)
                    .cross(vertices[static_cast<std::size_t>(tri[2])] - p0);
            const Corner& r = c[static_cast<std::size_t>(corner)];
            const double side = normal.dot(where(r.i, r.j, r.k) - p0);
            if ((r.value < 0.0) == (side > 0.0)) std::swap(tri[1], tri[2]);
            out.triangles.push_back(tri);
          }
        }
      }
    }
  }
  out.vertices.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t v = 0; v < vertices.size(); ++v)
    out.vertices.col(static_cast<Eigen::Index>(v)) = vertices[v];
  return out;
}

}  // namespace animrt::learn::seq_corpus
