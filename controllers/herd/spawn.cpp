#include "spawn.hpp"

#include <cmath>

namespace animrt::herd {
namespace {

constexpr int kSampleAttempts = 10000;
// The fallback grid's step, in spawn spacings: fine enough that the scan
// fills the gaps round figures already placed and packs rows staggered.
constexpr double kGridStep = 0.25;

bool apart(Vec2 p, double radius, std::span<const Agent> placed, std::span<const Vec2> own) {
  for (const Agent& b : placed) {
    if (norm(b.position - p) < kSpawnSpacing * (radius + b.radius)) return false;
  }
  for (const Vec2& q : own) {
    if (norm(q - p) < kSpawnSpacing * 2 * radius) return false;
  }
  return true;
}

std::optional<std::vector<Vec2>> sample(const Rect& area, int count, double radius,
                                        std::span<const Agent> placed,
                                        const std::function<bool(Vec2)>& clear,
                                        std::mt19937_64& rng) {
  std::uniform_real_distribution<double> ux(area.xmin, area.xmax);
  std::uniform_real_distribution<double> uy(area.ymin, area.ymax);
  std::vector<Vec2> out;
  for (int k = 0; k < count; ++k) {
    bool found = false;
    for (int attempt = 0; attempt < kSampleAttempts && !found; ++attempt) {
      const Vec2 p{ux(rng), uy(rng)};
      found = apart(p, radius, placed, out) && clear(p);
      if (found) out.push_back(p);
    }
    if (!found) return std::nullopt;
  }
  return out;
}

std::optional<std::vector<Vec2>> scan(const Rect& area, int count, double radius,
                                      std::span<const Agent> placed,
                                      const std::function<bool(Vec2)>& clear) {
  const double step = kGridStep * kSpawnSpacing * 2 * radius;
  const long nx = std::lround(std::floor((area.xmax - area.xmin) / step));
  const long ny = std::lround(std::floor((area.ymax - area.ymin) / step));
  std::vector<Vec2> out;
  for (long j = 0; j <= ny; ++j) {
    for (long i = 0; i <= nx; ++i) {
      const Vec2 p{area.xmin + static_cast<double>(i) * step,
                   area.ymin + static_cast<double>(j) * step};
      if (!apart(p, radius, placed, out) || !clear(p)) continue;
      out.push_back(p);
      if (static_cast<int>(out.size()) == count) return out;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::vector<Vec2>> spawn_positions(const Rect& area, int count, double radius,
                                                 std::span<const Agent> placed,
                                                 const std::function<bool(Vec2)>& clear,
                                                 std::mt19937_64& rng) {
  if (count <= 0) return std::vector<Vec2>{};
  if (auto sampled = sample(area, count, radius, placed, clear, rng)) return sampled;
  return scan(area, count, radius, placed, clear);
}

}  // namespace animrt::herd
