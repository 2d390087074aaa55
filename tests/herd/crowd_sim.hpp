#pragma once
// A plain figure model for crowd tests, the kind the herd drives: forward
// speed is the desired velocity's component along the heading, clamped to
// [0, vmax]; the heading turns toward the desired velocity at most
// max_turn * dt per step; the figure moves along its heading.

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/crowd.hpp"
#include "animrt/controllers/herd/nav_world.hpp"

namespace animrt::herd::test {

inline double wrap_angle(double a) { return std::remainder(a, 2 * M_PI); }

inline void move_figures(std::span<Agent> agents, std::span<const Vec2> desired,
                         std::span<const double> vmax, double dt, double max_turn) {
  for (std::size_t i = 0; i < agents.size(); ++i) {
    Agent& a = agents[i];
    const Vec2 d = desired[i];
    double turn = 0.0;
    if (norm(d) > 1e-9) {
      const double err = wrap_angle(std::atan2(d.y, d.x) - a.heading);
      turn = std::clamp(err / dt, -max_turn, max_turn);
    }
    a.heading = wrap_angle(a.heading + turn * dt);
    a.turn = turn;
    a.speed = std::clamp(dot(d, heading_vector(a.heading)), 0.0, vmax[i]);
    a.position += heading_vector(a.heading) * (a.speed * dt);
  }
}

// Pairs of agents closer than the sum of their radii.
inline int count_collisions(std::span<const Agent> agents) {
  int n = 0;
  for (std::size_t i = 0; i < agents.size(); ++i) {
    for (std::size_t j = i + 1; j < agents.size(); ++j) {
      const double r = agents[i].radius + agents[j].radius;
      if (norm2(agents[i].position - agents[j].position) < r * r) ++n;
    }
  }
  return n;
}

// Agents placed at random in a rectangle, at least `gap` apart, facing `heading`.
inline void spawn(std::vector<Agent>& agents, int count, Rect area, double radius, double gap,
                  double heading, int group, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> ux(area.xmin, area.xmax), uy(area.ymin, area.ymax);
  for (int k = 0; k < count;) {
    const Vec2 p{ux(rng), uy(rng)};
    bool ok = true;
    for (const Agent& a : agents) ok = ok && norm(a.position - p) >= gap;
    if (!ok) continue;
    Agent a;
    a.position = p;
    a.heading = heading;
    a.radius = radius;
    a.group = group;
    agents.push_back(a);
    ++k;
  }
}

// The red-versus-blue crossing: a 40 m x 20 m ground, a wall across x = 0
// with two gaps (y in [-5, -1], which the moving obstacle can close, and y
// in [3, 6]).
inline NavWorldConfig crossing_world(bool moving_obstacle) {
  NavWorldConfig c;
  c.bounds = {-20, -10, 20, 10};
  c.walls = {{{0, -7.5}, {0.5, 5}, 0.0}, {{0, 1}, {0.5, 4}, 0.0}, {{0, 8}, {0.5, 4}, 0.0}};
  if (moving_obstacle) c.moving = {{{{0, -3}, {0.5, 4}, 0.0}, 8.0, 0.5, 0.0}};
  c.agent_radius_m = 0.25;
  return c;
}

struct CrossingResult {
  int collisions = 0;       // colliding pairs summed over steps
  int wall_contacts = 0;    // agent-steps overlapping a wall or a dropped obstacle
  std::size_t arrived = 0;  // agents at their slots at the end
  std::size_t agents = 0;
  double max_time_ratio = 0.0;  // arrival time / (straight distance to target / top speed)
  double t_end = 0.0;
  int deferred_drops = 0;
  int drops = 0;
  std::vector<Vec2> final_positions;
};

inline CrossingResult run_crossing(double vlo, double vhi, bool moving_obstacle, int per_team,
                                   std::uint64_t seed, double t_max, CrowdParams params = {},
                                   double slot_spacing = 0.0) {
  NavWorld world(crossing_world(moving_obstacle));
  std::vector<Agent> agents;
  std::mt19937_64 rng(seed);
  const double r = 0.25;
  spawn(agents, per_team, {-18, -8, -14, 8}, r, 0.8, 0.0, 0, rng);
  spawn(agents, per_team, {14, -8, 18, 8}, r, 0.8, M_PI, 1, rng);
  Crowd crowd(world, agents, params);
  std::vector<int> red, blue;
  for (int i = 0; i < per_team; ++i) {
    red.push_back(i);
    blue.push_back(per_team + i);
  }
  CrowdGroupParams pr{{16, 0}, vlo, vhi, seed * 2 + 1};
  pr.slot_spacing_m = slot_spacing;
  CrowdGroupParams pb = pr;
  pb.target = {-16, 0};
  pb.seed = seed * 2 + 2;
  CrowdGroup g_red(crowd, agents, red, pr);
  CrowdGroup g_blue(crowd, agents, blue, pb);
  std::vector<double> vmax(agents.size());
  std::vector<double> ideal(agents.size());
  std::vector<double> arrival(agents.size(), -1.0);
  for (std::size_t k = 0; k < red.size(); ++k) {
    vmax[static_cast<std::size_t>(red[k])] = g_red.max_speed(k);
    vmax[static_cast<std::size_t>(blue[k])] = g_blue.max_speed(k);
  }
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const Vec2 tgt = agents[i].group == 0 ? Vec2{16, 0} : Vec2{-16, 0};
    ideal[i] = norm(tgt - agents[i].position) / vmax[i];
  }
  std::vector<Vec2> desired(agents.size());
  CrossingResult res;
  res.agents = agents.size();
  const double dt = 0.1;
  double t = 0.0;
  for (; t < t_max; t += dt) {
    g_red.steer(t, dt, agents, desired);
    g_blue.steer(t, dt, agents, desired);
    move_figures(agents, desired, vmax, dt, 0.6);
    res.collisions += count_collisions(agents);
    for (const Agent& a : agents) res.wall_contacts += world.in_wall(a.position, a.radius) ? 1 : 0;
    for (std::size_t k = 0; k < red.size(); ++k) {
      for (auto [g, m] : {std::pair{&g_red, red[k]}, std::pair{&g_blue, blue[k]}}) {
        if (g->arrived(k) && arrival[static_cast<std::size_t>(m)] < 0) {
          arrival[static_cast<std::size_t>(m)] = t + dt;
        }
      }
    }
    if (g_red.arrived_count() + g_blue.arrived_count() == agents.size()) break;
  }
  res.t_end = t;
  res.arrived = g_red.arrived_count() + g_blue.arrived_count();
  for (std::size_t i = 0; i < agents.size(); ++i) {
    const double ta = arrival[i] < 0 ? t_max : arrival[i];
    res.max_time_ratio = std::max(res.max_time_ratio, ta / ideal[i]);
    res.final_positions.push_back(agents[i].position);
  }
  res.deferred_drops = world.deferred_drops();
  res.drops = world.drops();
  return res;
}

}  // namespace animrt::herd::test
