// Quadric error edge collapse (see triangle_mesh.hpp).

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

#include "animrt/learn/seq_corpus/triangle_mesh.hpp"

namespace animrt::learn::seq_corpus {
namespace {

// A collapse may not leave a triangle worse than this (4 sqrt 3 area over
// the sum of squared edges: 1 equilateral, 0 flat), nor turn one by more
// than about 78 degrees.
constexpr double kMinQuality = 0.08;
constexpr double kMinNormalCos = 0.2;

using Quadric = Eigen::Matrix4d;

double quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double area2 = (b - a).cross(c - a).norm();  // twice the area
  const double edges = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return edges > 0.0 ? 2.0 * std::sqrt(3.0) * area2 / edges : 0.0;
}

struct Candidate {
  double cost;
  int u, v;
  unsigned version_u, version_v;
  Eigen::Vector3d at;
  bool operator<(const Candidate& o) const {  // for a min-heap on cost
    if (cost != o.cost) return cost > o.cost;
    return u != o.u ? u > o.u : v > o.v;
  }
};

class Decimator {
 public:
  explicit Decimator(const TriangleMesh& mesh) {
    const auto n = static_cast<std::size_t>(mesh.vertices.cols());
    pos_.resize(n);
    quadric_.assign(n, Quadric::Zero());
    faces_of_.resize(n);
    version_.assign(n, 0);
    alive_v_.assign(n, 1);
    alive_count_ = static_cast<int>(n);
    for (std::size_t v = 0; v < n; ++v) pos_[v] = mesh.vertices.col(static_cast<Eigen::Index>(v));
    faces_ = mesh.triangles;
    alive_f_.assign(faces_.size(), 1);
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      const auto& t = faces_[f];
      const Eigen::Vector3d normal =
          (pos_[u(t[1])] - pos_[u(t[0])]).cross(pos_[u(t[2])] - pos_[u(t[0])]);
      const double area2 = normal.norm();
      if (area2 > 0.0) {
        const Eigen::Vector3d nn = normal / area2;
        Eigen::Vector4d plane(nn.x(), nn.y(), nn.z(), -nn.dot(pos_[u(t[0])]));
        // Area weighted, so big flat regions hold their place.
        const Quadric q = 0.5 * area2 * plane * plane.transpose();
        for (int c : t) quadric_[u(c)] += q;
      }
      for (int c : t) faces_of_[u(c)].push_back(static_cast<int>(f));
    }
    for (const auto& t : faces_) {
      for (int c = 0; c < 3; ++c) {
        const int a = t[static_cast<std::size_t>(c)], b = t[static_cast<std::size_t>((c + 1) % 3)];
        if (a < b) push(a, b);
      }
    }
  }

  void run(int target) {
    while (alive_count_ > target && !heap_.empty()) {
      const Candidate c = heap_.top();
      heap_.pop();
      if (!alive_v_[u(c.u)] || !alive_v_[u(c.v)] || version_[u(c.u)] != c.version_u ||
          version_[u(c.v)] != c.version_v)
        continue;
      if (!can_collapse(c.u, c.v, c.at)) continue;
      collapse(c.u, c.v, c.at);
    }
  }

  TriangleMesh result() const {
    TriangleMesh out;
    std::vector<int> renumber(pos_.size(), -1);
    std::vector<int> kept;
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      if (!alive_f_[f]) continue;
      std::array<int, 3> t{};
      for (int c = 0; c < 3; ++c) {
        int& r = renumber[u(faces_[f][static_cast<std::size_t>(c)])];
        if (r < 0) {
          r = static_cast<int>(kept.size());
          kept.push_back(faces_[f][static_cast<std::size_t>(c)]);
        }
        t[static_cast<std::size_t>(c)] = r;
      }
      out.triangles.push_back(t);
    }
    out.vertices.resize(3, static_cast<Eigen::Index>(kept.size()));
    for (std::size_t v = 0; v < kept.size(); ++v)
      out.vertices.col(static_cast<Eigen::Index>(v)) = pos_[u(kept[v])];
    return out;
  }

 private:
  static std::size_t u(int i) { return static_cast<std::size_t>(i); }

  void neighbours(int v, std::vector<int>& out) const {
    out.clear();
    for (int f : faces_of_[u(v)]) {
      if (!alive_f_[u(f)]) continue;
      for (int c : faces_[u(f)])
        if (c != v) out.push_back(c);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  void push(int a, int b) {
    const Quadric q = quadric_[u(a)] + quadric_[u(b)];
    const Eigen::Vector3d pa = pos_[u(a)], pb = pos_[u(b)], mid = 0.5 * (pa + pb);
    const auto cost = [&q](const Eigen::Vector3d& x) {
      const Eigen::Vector4d h(x.x(), x.y(), x.z(), 1.0);
      return std::max(0.0, h.dot(q * h));
    };
    Eigen::Vector3d best = mid;
    const Eigen::Matrix3d a3 = q.topLeftCorner<3, 3>();
    const Eigen::Vector3d b3 = q.topRightCorner<3, 1>();
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(a3);
    bool solved = false;
    if (lu.rank() == 3) {
      const Eigen::Vector3d x = lu.solve(-b3);
      // An optimum far off the edge comes from a nearly flat quadric.
      if (x.allFinite() && (x - mid).norm() <= (pb - pa).norm()) {
        best = x;
        solved = true;
      }
    }
    if (!solved) {
      for (const Eigen::Vector3d& x : {pa, pb})
        if (cost(x) < cost(best)) best = x;
    }
    heap_.push({cost(best), a, b, version_[u(a)], version_[u(b)], best});
  }

  bool can_collapse(int a, int b, const Eigen::Vector3d& at) {
    // Link condition: the ends share exactly the two vertices across the edge.
    neighbours(a, na_);
    neighbours(b, nb_);
    shared_.clear();
    std::set_intersection(na_.begin(), na_.end(), nb_.begin(), nb_.end(),
                          std::back_inserter(shared_));
    if (shared_.size() != 2) return false;
    if (alive_count_ <= 4) return false;
    for (int end : {a, b}) {
      for (int f : faces_of_[u(end)]) {
        if (!alive_f_[u(f)]) continue;
        const auto& t = faces_[u(f)];
        const bool has_a = t[0] == a || t[1] == a || t[2] == a;
        const bool has_b = t[0] == b || t[1] == b || t[2] == b;
        if (has_a && has_b) continue;  // removed by the collapse
        std::array<Eigen::Vector3d, 3> p{pos_[u(t[0])], pos_[u(t[1])], pos_[u(t[2])]};
        const Eigen::Vector3d n0 = (p[1] - p[0]).cross(p[2] - p[0]);
        for (int c = 0; c < 3; ++c)
          if (t[static_cast<std::size_t>(c)] == end) p[static_cast<std::size_t>(c)] = at;
        const Eigen::Vector3d n1 = (p[1] - p[0]).cross(p[2] - p[0]);
        if (n1.dot(n0) <= kMinNormalCos * n0.norm() * n1.norm()) return false;
        if (quality(p[0], p[1], p[2]) < kMinQuality) return false;
      }
    }
    return true;
  }

  void collapse(int a, int b, const Eigen::Vector3d& at) {
    for (int f : faces_of_[u(b)]) {
      if (!alive_f_[u(f)]) continue;
      auto& t = faces_[u(f)];
      if (t[0] == a || t[1] == a || t[2] == a) {
        alive_f_[u(f)] = 0;
        continue;
      }
      for (int& c : t)
        if (c == b) c = a;
      faces_of_[u(a)].push_back(f);
    }
    // Drop dead faces from the lists of the vertices around.
    neighbours(a, na_);
    for (int w : na_) {
      auto& list = faces_of_[u(w)];
      list.erase(
          std::remove_if(list.begin(), list.end(), [this](int f) { return !alive_f_[u(f)]; }),
          list.end());
    }
    auto& list = faces_of_[u(a)];
    list.erase(std::remove_if(list.begin(), list.end(), [this](int f) { return !alive_f_[u(f)]; }),
               list.end());
    faces_of_[u(b)].clear();
    alive_v_[u(b)] = 0;
    --alive_count_;
    pos_[u(a)] = at;
    quadric_[u(a)] += quadric_[u(b)];
    ++version_[u(a)];
    ++version_[u(b)];
    for (int w : na_) push(std::min(a, w), std::max(a, w));
  }

  std::vector<Eigen::Vector3d> pos_;
  std::vector<Quadric> quadric_;
  std::vector<std::array<int, 3>> faces_;
  std::vector<char> alive_f_, alive_v_;
  std::vector<std::vector<int>> faces_of_;
  std::vector<unsigned> version_;
  std::priority_queue<Candidate> heap_;
  int alive_count_ = 0;
  std::vector<int> na_, nb_, shared_;  // scratch
};

}  // namespace

TriangleMesh decimate(const TriangleMesh& mesh, int target_vertices) {
  Decimator d(mesh);
  d.run(target_vertices);
  return d.result();
}

}  // namespace animrt::learn::seq_corpus
