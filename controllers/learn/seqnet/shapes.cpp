#include "animrt/learn/seqnet/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "animrt/controllers/seqnet/deformation.hpp"

namespace animrt::seqnet {

MeshSequence make_bar(int rings, int around, double length) {
  MeshSequence out;
  const int v = rings * around + 2;
  Positions p(3, v);
  for (int r = 0; r < rings; ++r) {
    const double z = length * r / (rings - 1);
    for (int a = 0; a < around; ++a) {
      const double phi = 2.0 * std::numbers::pi * a / around;
      p.col(r * around + a) << std::cos(phi), std::sin(phi), z;
    }
  }
  const int bottom = rings * around, top = bottom + 1;
  p.col(bottom) << 0, 0, 0;
  p.col(top) << 0, 0, length;
  auto at = [&](int r, int a) { return r * around + (a % around); };
  for (int r = 0; r + 1 < rings; ++r) {
    for (int a = 0; a < around; ++a) {
      out.triangles.push_back({at(r, a), at(r, a + 1), at(r + 1, a + 1)});
      out.triangles.push_back({at(r, a), at(r + 1, a + 1), at(r + 1, a)});
    }
  }
  for (int a = 0; a < around; ++a) {
    out.triangles.push_back({bottom, at(0, a + 1), at(0, a)});
    out.triangles.push_back({top, at(rings - 1, a), at(rings - 1, a + 1)});
  }
  out.frames.push_back(std::move(p));
  return out;
}

MeshSequence make_twisting_bar(int rings, int around, double length, double total_angle,
                               int frames) {
  MeshSequence out = make_bar(rings, around, length);
  const Positions rest = out.frames.front();
  out.frames.clear();
  for (int f = 0; f < frames; ++f) {
    const double progress = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.0;
    Positions p = rest;
    for (Eigen::Index i = 0; i < p.cols(); ++i) {
      const double u = std::clamp((rest(2, i) / length - 0.25) / 0.5, 0.0, 1.0);
      const double angle = total_angle * progress * u * u * (3.0 - 2.0 * u);
      const double c = std::cos(angle), s = std::sin(angle);
      p(0, i) = c * rest(0, i) - s * rest(1, i);
      p(1, i) = s * rest(0, i) + c * rest(1, i);
    }
    out.frames.push_back(std::move(p));
  }
  out.clips.push_back(Clip{"twist", 0, frames, 0.0});
  return out;
}

MeshSequence make_icosphere(int levels) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& p : v) p.normalize();
  Triangles t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> middle;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto found = middle.find(key);
      if (found != middle.end()) return found->second;
      v.push_back((v[a] + v[b]).normalized());
      const int index = static_cast<int>(v.size()) - 1;
      middle[key] = index;
      return index;
    };
    Triangles next;
    for (const auto& f : t) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  MeshSequence out;
  out.triangles = std::move(t);
  Positions p(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) p.col(static_cast<Eigen::Index>(i)) = v[i];
  out.frames.push_back(std::move(p));
  return out;
}

}  // namespace animrt::seqnet
