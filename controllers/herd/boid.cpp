#include "animrt/controllers/herd/boid.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "animrt/controllers/herd/wander_leader.hpp"

namespace animrt::herd {

Vec2 random_in_unit_disc(std::mt19937_64& rng) {
  for (;;) {
    const Vec2 p{2.0 * unit_uniform(rng) - 1.0, 2.0 * unit_uniform(rng) - 1.0};
    if (norm2(p) <= 1.0) return p;
  }
}

Vec2 random_unit_vector(std::mt19937_64& rng) {
  return heading_vector(2.0 * std::numbers::pi * unit_uniform(rng));
}

Vec2 rotate_towards(Vec2 current, Vec2 target, double max_radians, double max_length_delta) {
  const double lc = norm(current);
  const double lt = norm(target);
  if (lc == 0.0 || lt == 0.0) {
    const Vec2 d = target - current;
    const double ld = norm(d);
    return ld <= max_length_delta || ld == 0.0 ? target : current + d * (max_length_delta / ld);
  }
  const double angle = std::atan2(cross(current, target), dot(current, target));
  const double a = std::clamp(angle, -max_radians, max_radians);
  const Vec2 u = current / lc;
  const Vec2 dir{u.x * std::cos(a) - u.y * std::sin(a), u.x * std::sin(a) + u.y * std::cos(a)};
  const double len = lc + std::clamp(lt - lc, -max_length_delta, max_length_delta);
  return dir * len;
}

void check_members(std::span<const int> members, const char* who) {
  std::vector<int> sorted(members.begin(), members.end());
  std::sort(sorted.begin(), sorted.end());
  if (!sorted.empty() && sorted.front() < 0)
    throw std::invalid_argument(std::string(who) + ": member index " +
                                std::to_string(sorted.front()) + " is negative");
  const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
  if (dup != sorted.end())
    throw std::invalid_argument(std::string(who) + ": member index " + std::to_string(*dup) +
                                " appears twice");
}

std::size_t herd_size_needed(std::span<const int> members) {
  int m = -1;
  for (const int i : members) m = std::max(m, i);
  return static_cast<std::size_t>(m + 1);
}

}  // namespace animrt::herd
