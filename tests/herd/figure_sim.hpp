#pragma once
// A simple walking figure for the flock tests: it turns toward the desired
// velocity by at most max_turn*dt, walks forward only (at the desired
// velocity's component along its heading, within [0, vmax]), with its speed
// changing by at most accel*dt per step. Plus the measures the tests check.

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/wander_leader.hpp"

namespace animrt::herd::test {

struct FigureLimits {
  double vmax = 0.12;     // m/s
  double accel = 0.1;     // m/s^2
  double max_turn = 0.6;  // rad/s
};

inline void walk(std::span<Agent> agents, std::span<const Vec2> desired, const FigureLimits& lim,
                 double dt) {
  for (std::size_t i = 0; i < agents.size(); ++i) {
    Agent& a = agents[i];
    const Vec2 d = desired[i];
    double turn = 0.0;
    if (norm2(d) > 0.0) {
      const double err = angle_diff(std::atan2(d.y, d.x), a.heading);
      turn = std::clamp(err, -lim.max_turn * dt, lim.max_turn * dt);
    }
    a.heading = std::remainder(a.heading + turn, 2.0 * 3.141592653589793);
    a.turn = turn / dt;
    const double want = std::clamp(dot(d, heading_vector(a.heading)), 0.0, lim.vmax);
    a.speed += std::clamp(want - a.speed, -lim.accel * dt, lim.accel * dt);
    a.position += heading_vector(a.heading) * (a.speed * dt);
  }
}

// |sum v| / (N mean |v|) over the given agents (0 when all stand).
inline double order_parameter(std::span<const Agent> agents) {
  Vec2 sum;
  double speeds = 0.0;
  for (const Agent& a : agents) {
    sum += a.velocity();
    speeds += std::abs(a.speed);
  }
  return speeds > 0.0 ? norm(sum) / speeds : 0.0;
}

// Pairs closer than the sum of their radii.
inline int collisions(std::span<const Agent> agents) {
  int c = 0;
  for (std::size_t i = 0; i < agents.size(); ++i)
    for (std::size_t j = i + 1; j < agents.size(); ++j)
      if (norm(agents[i].position - agents[j].position) < agents[i].radius + agents[j].radius) ++c;
  return c;
}

// n figures on a jittered square lattice of the given spacing around
// `center`, all facing `heading`, standing, in group `group`.
inline std::vector<Agent> lattice(int n, Vec2 center, double spacing, double heading, int group,
                                  unsigned seed) {
  std::mt19937_64 rng(seed);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::vector<Agent> out;
  for (int k = 0; k < n; ++k) {
    Agent a;
    const double jx = (unit_uniform(rng) - 0.5) * 0.2 * spacing;
    const double jy = (unit_uniform(rng) - 0.5) * 0.2 * spacing;
    a.position = center + Vec2{(k % side - (side - 1) / 2.0) * spacing + jx,
                               (k / side - (side - 1) / 2.0) * spacing + jy};
    a.heading = heading;
    a.group = group;
    out.push_back(a);
  }
  return out;
}

}  // namespace animrt::herd::test
